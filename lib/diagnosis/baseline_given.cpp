// The user's simulation model as the diagnosis' baseline (see
// baseline_given.hpp).
#include "diagnosis/baseline_given.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "diagnosis/candidates.hpp"
#include "diagnosis/mean_fit.hpp"
#include "effects/registry.hpp"

namespace umbmark::diag {

std::string GivenModel::Check() const {
  if (auto e = params.Check(); !e.empty()) return fmt::format("{}: {}", source, e);
  if (!noise_given) return {};
  if (!(std::isfinite(k_L) && k_L >= 0.0)) return fmt::format("--kl = {} must be finite and >= 0 [m^1/2]", k_L);
  if (!(std::isfinite(k_R) && k_R >= 0.0)) return fmt::format("--kr = {} must be finite and >= 0 [m^1/2]", k_R);
  if (!(k_L > 0.0 || k_R > 0.0)) return "--kl and --kr are both 0: a model without wheel noise cannot be compared";
  return {};
}

ParamVector GivenParams(const RobotParams& recorded, const RobotParams& given) {
  ParamVector p = NominalParams();
  const double cL = given.wheel_diameter_left_m / recorded.wheel_diameter_left_m;
  const double cR = given.wheel_diameter_right_m / recorded.wheel_diameter_right_m;
  p[kParamEb] = given.wheelbase_m / recorded.wheelbase_m;
  p[kParamEd] = cR / cL;
  p[kParamScale] = 0.5 * (cL + cR) - 1.0;
  return p;
}

BaselineFit FitGivenBaseline(const CampaignData& c, const MeanModel& model, const GivenModel& given,
                             const BaselineFitOptions& options) {
  BaselineFit b;
  b.free.clear();
  b.given = true;
  b.p = GivenParams(c.robot, given.params);
  NoiseParams noise;
  StartGroundTruthNoise(c, options, b, noise);
  b.noise_fit.fit_wheel_noise = !given.noise_given;
  b.wheel_noise_source = given.noise_given ? "given" : "fitted";
  if (given.noise_given) {
    // A wheel given as noise-free keeps a tiny variance: the covariances
    // must stay invertible.
    noise.kL2 = std::max(given.k_L * given.k_L, b.noise_fit.min_k2);
    noise.kR2 = std::max(given.k_R * given.k_R, b.noise_fit.min_k2);
  }
  model.Residuals(b.p, b.eps);
  b.bases = ComputeBases(c, model, b.p);
  b.noise = FitPieceNoise(b.eps, b.bases, c.pieces, {}, noise, b.noise_fit);
  b.W = Whiteners(b.bases, c.pieces, b.noise);
  FitPiecesGroundTruth(c, b);
  b.D = Eigen::MatrixXd(static_cast<Eigen::Index>(b.eps.size()), 0);
  b.cov = Eigen::MatrixXd(0, 0);
  b.notes.push_back(fmt::format(
      "baseline: the given model from {} (wheelbase {:.4f} m, wheel diameters {:.5f} / {:.5f} m: E_d = {:.6f}, "
      "E_b = {:.6f}, scale {:+.4f} % relative to the recorded robot), wheel noise {}",
      given.source, given.params.wheelbase_m, given.params.wheel_diameter_left_m,
      given.params.wheel_diameter_right_m, b.p[kParamEd], b.p[kParamEb], 100.0 * b.p[kParamScale],
      given.noise_given ? fmt::format("given (k_L = {:.3g}, k_R = {:.3g} m^1/2)", given.k_L, given.k_R)
                        : fmt::format("not given: fitted (k_L = {:.3g}, k_R = {:.3g} m^1/2; {} is not a candidate)",
                                      std::sqrt(b.noise.kL2), std::sqrt(b.noise.kR2),
                                      NoiseEffectName(effects::NoiseTerm::kWheelNoise))));
  return b;
}

std::vector<sim::EffectKind> GivenModelCandidates(const GivenModel& given) {
  // The parameter errors in catalogue order; the wheel noise's only when it
  // is given.
  std::vector<sim::EffectKind> out;
  for (sim::EffectKind k : sim::ParameterErrorEffects())
    if (given.noise_given || NoiseTermOf(k) != effects::NoiseTerm::kWheelNoise) out.push_back(k);
  return out;
}

namespace {

/// What the parameter errors' hooks (Effect::DescribeGiven, ...) need.
effects::GivenContext ContextOf(const RobotParams& recorded, const GivenModel& given) {
  const ParamVector g = GivenParams(recorded, given.params);
  effects::GivenContext x;
  x.recorded = recorded;
  x.given = given.params;
  x.E_d = g[kParamEd];
  x.E_b = g[kParamEb];
  x.scale = g[kParamScale];
  x.k_L = given.k_L;
  x.k_R = given.k_R;
  return x;
}

}  // namespace

std::map<std::string, double> DescribeGivenParams(sim::EffectKind kind, const std::map<std::string, double>& raw,
                                                  const RobotParams& recorded, const GivenModel& given) {
  return effects::Of(kind).DescribeGiven(raw, ContextOf(recorded, given));
}

std::map<std::string, double> DescribeGivenParamErrors(sim::EffectKind kind,
                                                       const std::map<std::string, double>& raw_se,
                                                       const RobotParams& recorded, const GivenModel& given) {
  return effects::Of(kind).DescribeGivenErrors(raw_se, ContextOf(recorded, given));
}

std::vector<ParameterCorrection> Corrections(sim::EffectKind kind, const std::map<std::string, double>& d,
                                             const GivenModel& given, double negligible) {
  // The corrections use the given model alone (GivenCorrection's values).
  effects::GivenContext x;
  x.given = given.params;
  x.k_L = given.k_L;
  x.k_R = given.k_R;
  const effects::Effect& e = effects::Of(kind);
  std::vector<ParameterCorrection> out;
  for (effects::GivenCorrection& c : e.GivenCorrections(d, x, negligible))
    out.push_back({std::string(e.Name()), std::move(c.parameter), c.given, c.corrected, std::move(c.unit),
                   std::move(c.text)});
  return out;
}

}  // namespace umbmark::diag
