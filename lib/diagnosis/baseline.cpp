// Baseline of the diagnosis (see baseline.hpp).
#include "diagnosis/baseline.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <variant>

#include <fmt/format.h>

#include "calibration/refine.hpp"

namespace umbmark::diag {

const std::vector<int>& BaselineParams() {
  static const std::vector<int> params = {kParamEd, kParamEb};
  return params;
}

BaselineStart StartBaseline(const CampaignData& c, bool use_refine) {
  BaselineStart s;
  s.p = NominalParams();
  s.description = "nominal (E_d = E_b = 1)";
  if (!use_refine) return s;
  try {
    RefineOptions ro;
    ro.scale = ScaleMode::kFixed;
    std::vector<TrajectoryRunSet> tsets;
    std::vector<SquareRunSet> ssets;
    for (std::size_t e = 0; e < c.experiments.size(); ++e) {
      if (const auto* t = std::get_if<TrajectoryData>(&c.files[e])) {
        tsets.push_back({c.robot, t});
      } else {
        SquareRunSet sq;
        sq.side_m = c.experiments[e].side_m;
        sq.recorded = c.robot;
        sq.source = c.experiments[e].file;
        sq.errors = std::get<EndpointData>(c.files[e]).runs;
        ssets.push_back(sq);
      }
    }
    const RefineSummary rs = tsets.empty() ? RefineFromReturnErrors(ssets, c.robot, ro)
                                           : RefineFromTrajectories(tsets, c.robot, ro);
    if (std::isfinite(rs.E_d) && std::isfinite(rs.E_b) && rs.E_d > 0.5 && rs.E_d < 2.0 && rs.E_b > 0.5 &&
        rs.E_b < 2.0) {
      s.p[kParamEd] = rs.E_d;
      s.p[kParamEb] = rs.E_b;
      s.description = fmt::format("refined calibration ({}): E_d = {:.6f}, E_b = {:.6f}",
                                  tsets.empty() ? "return errors" : "trajectories", rs.E_d, rs.E_b);
      s.refined = true;
    }
  } catch (const std::exception& e) {
    s.notes.push_back(std::string("refined calibration unavailable, starting from the nominal robot: ") + e.what());
  }
  return s;
}

const char* GroundTruthNoiseSourceToString(GroundTruthNoiseSource g) {
  return g == GroundTruthNoiseSource::kStandstills ? "standstills" : "fitted";
}

const char* WheelNoiseSourceToString(WheelNoiseSource w) {
  return w == WheelNoiseSource::kRepeats ? "repeats" : "fitted";
}

std::string BaselineFitOptions::Check() const {
  if (rounds < 1) return fmt::format("rounds = {} must be >= 1", rounds);
  if (std::string e = standstill.Check(); !e.empty()) return "standstill." + e;
  if (std::string e = repeat.Check(); !e.empty()) return "repeat." + e;
  return {};
}

void StartGroundTruthNoise(const CampaignData& c, const BaselineFitOptions& options, BaselineFit& b,
                           NoiseParams& noise) {
  b.ground_truth_known = c.ground_truth.has_value();
  b.standstill = MeasureStandstillNoise(c, options.standstill);
  // Floors: 1 micrometre / 1 microradian keep noise-free ground truth usable.
  b.noise_fit.min_sigma_xy2 = 1e-12;
  b.noise_fit.min_sigma_theta2 = 1e-12;
  b.noise_fit.fit_ground_truth = false;
  if (b.ground_truth_known) {
    b.ground_truth_source = "manifest";
    noise.sxy2 = std::max(c.ground_truth->sigma_xy_m * c.ground_truth->sigma_xy_m, 1e-12);
    noise.sth2 = std::max(c.ground_truth->sigma_theta_rad * c.ground_truth->sigma_theta_rad, 1e-12);
  } else if (options.ground_truth == GroundTruthNoiseSource::kStandstills && b.standstill.measured) {
    b.ground_truth_source = "standstills";
    noise.sxy2 = b.standstill.sigma_xy_m * b.standstill.sigma_xy_m;
    noise.sth2 = b.standstill.sigma_theta_rad * b.standstill.sigma_theta_rad;
  } else {
    b.ground_truth_source = "fitted";
    b.noise_fit.fit_ground_truth = true;
    noise.sxy2 = 1e-8;
    noise.sth2 = 1e-6;
  }
}

void FitPiecesGroundTruth(const CampaignData& c, BaselineFit& b) {
  if (b.ground_truth_source != "standstills") return;
  PieceNoiseFitOptions o = b.noise_fit;
  o.fit_ground_truth = true;
  const NoiseParams n = FitPieceNoise(b.eps, b.bases, c.pieces, {}, b.noise, o);
  b.pieces_sigma_xy_m = std::sqrt(n.sxy2);
  b.pieces_sigma_theta_rad = std::sqrt(n.sth2);
}

void FitPiecesWheelNoise(const CampaignData& c, BaselineFit& b) {
  if (b.wheel_noise_source != "repeats") return;
  PieceNoiseFitOptions o = b.noise_fit;
  o.fit_wheel_noise = true;
  const NoiseParams n = FitPieceNoise(b.eps, b.bases, c.pieces, {}, b.noise, o);
  b.pieces_k_L = std::sqrt(n.kL2);
  b.pieces_k_R = std::sqrt(n.kR2);
}

namespace {

/// The wheel noise from the repeated runs' scatter at the start's residuals
/// (the contrasts hold no mean: where E_d, E_b start does not matter), held
/// fixed from here on when options.wheel is kRepeats and the design
/// supports it.
void StartWheelNoise(const CampaignData& c, const std::vector<double>& eps, const BaselineFitOptions& options,
                     BaselineFit& b, NoiseParams& noise) {
  b.repeat = MeasureRepeatNoise(c, eps, b.bases, noise, b.noise_fit, options.repeat);
  b.wheel_noise_source = "fitted";
  if (options.wheel != WheelNoiseSource::kRepeats || !b.repeat.measured) return;
  b.wheel_noise_source = "repeats";
  b.repeat_design = BuildRepeatDesign(c, b.bases, options.repeat);
  b.repeat_pairs = BuildRepeatDesign(c, b.bases, options.repeat, /*pairs=*/true);
  noise.kL2 = std::max(b.repeat.k_L * b.repeat.k_L, b.noise_fit.min_k2);
  noise.kR2 = std::max(b.repeat.k_R * b.repeat.k_R, b.noise_fit.min_k2);
  b.noise_fit.fit_wheel_noise = false;
}

}  // namespace

NoiseParams HeldWheelNoise(const CampaignData& c, const BaselineFit& b, const std::vector<double>& eps,
                           const std::vector<PieceBases>& bases, NoiseParams start, const PieceNoiseFitOptions& fit,
                           bool bumps) {
  if (b.wheel_noise_source != "repeats" || b.repeat_design.contrasts.empty()) return start;
  const NoiseParams r = FitRepeatWheelNoise(b.repeat_design, b.repeat_pairs, c, eps, bases, start, fit, bumps).noise;
  start.kL2 = std::max(r.kL2, fit.min_k2);
  start.kR2 = std::max(r.kR2, fit.min_k2);
  return start;
}

BaselineFit FitBaseline(const CampaignData& c, const MeanModel& model, const BaselineStart& start,
                        const BaselineFitOptions& options) {
  BaselineFit b;
  ParamVector p = start.p;
  NoiseParams noise;
  StartGroundTruthNoise(c, options, b, noise);
  std::vector<double> eps;
  model.Residuals(p, eps);
  b.bases = ComputeBases(c, model, p);
  StartWheelNoise(c, eps, options, b, noise);
  noise = FitPieceNoise(eps, b.bases, c.pieces, {}, noise, b.noise_fit);
  MeanFit base;
  for (int round = 0; round < options.rounds; ++round) {
    base = FitMean(model, p, BaselineParams(), Whiteners(b.bases, c.pieces, noise), options.mean);
    p = base.p;
    if (round == 0) b.bases = ComputeBases(c, model, p);
    noise = FitPieceNoise(base.eps, b.bases, c.pieces, {}, noise, b.noise_fit);
  }
  if (start.refined && base.cov.rows() == 2) {
    // The calibration and the model's best fit on the pieces should agree
    // when the model is right; far apart, systematic effects are at work.
    const ParamVector& p0 = start.p;
    const double zd = (p[kParamEd] - p0[kParamEd]) / std::sqrt(std::max(base.cov(0, 0), 1e-300));
    const double zb = (p[kParamEb] - p0[kParamEb]) / std::sqrt(std::max(base.cov(1, 1), 1e-300));
    if (std::max(std::abs(zd), std::abs(zb)) > 5.0)
      b.notes.push_back(fmt::format(
          "the refined calibration (E_d = {:.6f}, E_b = {:.6f}) and the baseline's best fit on the pieces (E_d = "
          "{:.6f}, E_b = {:.6f}) differ by {:.0f} and {:.0f} standard errors: the two weigh the runs differently, "
          "which matters only when the runs leave the model",
          p0[kParamEd], p0[kParamEb], p[kParamEd], p[kParamEb], zd, zb));
  }
  b.p = p;
  b.noise = noise;
  b.eps = base.eps;
  b.cov = base.cov;
  b.W = Whiteners(b.bases, c.pieces, noise);
  // Jacobian at the final point for the null refits and cross-validation.
  b.D = model.Jacobian(p, BaselineParams(), b.eps);
  FitPiecesGroundTruth(c, b);
  FitPiecesWheelNoise(c, b);
  return b;
}

}  // namespace umbmark::diag
