// The user's simulation model as the diagnosis' baseline (see
// baseline_given.hpp).
#include "diagnosis/baseline_given.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "diagnosis/candidates.hpp"
#include "diagnosis/mean_fit.hpp"

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

double Get(const std::map<std::string, double>& m, const char* key, double fallback) {
  const auto it = m.find(key);
  return it == m.end() ? fallback : it->second;
}

}  // namespace

std::map<std::string, double> DescribeGivenParams(sim::EffectKind kind, const std::map<std::string, double>& raw,
                                                  const RobotParams& recorded, const GivenModel& given) {
  const ParamVector g = GivenParams(recorded, given.params);
  switch (kind) {
    case sim::EffectKind::kWheelbaseError: {
      const double shown = Get(raw, "E_b", g[kParamEb]) * recorded.wheelbase_m;
      const double err = given.params.wheelbase_m - shown;
      return {{"wheelbase_m", shown},
              {"wheelbase_given_m", given.params.wheelbase_m},
              {"error_mm", 1e3 * err},
              {"relative_error", err / shown}};
    }
    case sim::EffectKind::kDiameterRatioError: {
      // E_d is relative to the recorded ratio; the scale (mean diameter
      // factor) stays the given model's.
      const double E_d = Get(raw, "E_d", g[kParamEd]);
      const double rec_ratio = recorded.wheel_diameter_right_m / recorded.wheel_diameter_left_m;
      const double shown = E_d * rec_ratio;
      const double given_ratio = given.params.wheel_diameter_right_m / given.params.wheel_diameter_left_m;
      const double scale = 1.0 + g[kParamScale];
      return {{"ratio", shown},
              {"ratio_given", given_ratio},
              {"error_ppm", 1e6 * (given_ratio / shown - 1.0)},
              {"wheel_diameter_left_m", recorded.wheel_diameter_left_m * scale * 2.0 / (E_d + 1.0)},
              {"wheel_diameter_right_m", recorded.wheel_diameter_right_m * scale * 2.0 * E_d / (E_d + 1.0)}};
    }
    case sim::EffectKind::kWheelNoiseError: {
      const double kL = Get(raw, "k_L", given.k_L), kR = Get(raw, "k_R", given.k_R);
      auto ratio = [](double fit, double giv) { return giv > 0.0 ? fit / giv : 0.0; };
      return {{"k_L", kL},
              {"k_R", kR},
              {"k_L_given", given.k_L},
              {"k_R_given", given.k_R},
              {"ratio_L", ratio(kL, given.k_L)},
              {"ratio_R", ratio(kR, given.k_R)}};
    }
    case sim::EffectKind::kScaleError: {
      // Relative to the given model's own mean diameter.
      std::map<std::string, double> out = raw;
      if (const auto it = raw.find("s"); it != raw.end()) out["s"] = (1.0 + it->second) / (1.0 + g[kParamScale]) - 1.0;
      return out;
    }
    default: return raw;
  }
}

std::map<std::string, double> DescribeGivenParamErrors(sim::EffectKind kind,
                                                       const std::map<std::string, double>& raw_se,
                                                       const RobotParams& recorded, const GivenModel& given) {
  if (kind == sim::EffectKind::kWheelbaseError) {
    const auto it = raw_se.find("E_b");
    if (it == raw_se.end()) return {};
    return {{"wheelbase_m", it->second * recorded.wheelbase_m}, {"error_mm", 1e3 * it->second * recorded.wheelbase_m}};
  }
  if (kind == sim::EffectKind::kDiameterRatioError) {
    const auto it = raw_se.find("E_d");
    if (it == raw_se.end()) return {};
    const double rec_ratio = recorded.wheel_diameter_right_m / recorded.wheel_diameter_left_m;
    return {{"ratio", it->second * rec_ratio}, {"error_ppm", 1e6 * it->second}};
  }
  if (kind == sim::EffectKind::kScaleError) {
    const ParamVector g = GivenParams(recorded, given.params);
    std::map<std::string, double> out = raw_se;
    if (const auto it = raw_se.find("s"); it != raw_se.end()) out["s"] = it->second / (1.0 + g[kParamScale]);
    return out;
  }
  return raw_se;
}

std::vector<ParameterCorrection> Corrections(sim::EffectKind kind, const std::map<std::string, double>& d,
                                             const GivenModel& given, double negligible) {
  std::vector<ParameterCorrection> out;
  const std::string name = sim::EffectToString(kind);
  if (kind == sim::EffectKind::kWheelbaseError) {
    const double err = Get(d, "error_mm", 0.0);
    out.push_back({name, "wheelbase_m", given.params.wheelbase_m, Get(d, "wheelbase_m", 0.0), "m",
                   fmt::format("the simulation's wheelbase is {:.2f} mm ({:.2f} %) too {}: set wheelbase_m = {:.5f} "
                               "(was {:.5f})",
                               std::abs(err), 100.0 * std::abs(Get(d, "relative_error", 0.0)),
                               err > 0.0 ? "long" : "short", Get(d, "wheelbase_m", 0.0), given.params.wheelbase_m)});
  } else if (kind == sim::EffectKind::kDiameterRatioError) {
    const double ppm = Get(d, "error_ppm", 0.0);
    const std::string text = fmt::format(
        "the simulation's wheel-diameter ratio D_R/D_L is {:.0f} ppm ({:.3f} %) too {}: set wheel_diameter_left_m "
        "= {:.6f}, wheel_diameter_right_m = {:.6f} (were {:.6f}, {:.6f}; mean diameter kept)",
        std::abs(ppm), 1e-4 * std::abs(ppm), ppm > 0.0 ? "large" : "small", Get(d, "wheel_diameter_left_m", 0.0),
        Get(d, "wheel_diameter_right_m", 0.0), given.params.wheel_diameter_left_m,
        given.params.wheel_diameter_right_m);
    out.push_back({name, "wheel_diameter_left_m", given.params.wheel_diameter_left_m,
                   Get(d, "wheel_diameter_left_m", 0.0), "m", text});
    out.push_back({name, "wheel_diameter_right_m", given.params.wheel_diameter_right_m,
                   Get(d, "wheel_diameter_right_m", 0.0), "m", text});
  } else if (kind == sim::EffectKind::kWheelNoiseError) {
    // A wheel whose k is within the practical threshold of the given one
    // (explanation.hpp: |k_fit / k_given - 1| < negligible) is consistent:
    // only the other wheel's k is to change.
    struct Wheel {
      const char* side;
      const char* key;
      double given, fit, ratio;
    };
    const Wheel wheels[2] = {{"left", "k_L", given.k_L, Get(d, "k_L", 0.0), Get(d, "ratio_L", 0.0)},
                             {"right", "k_R", given.k_R, Get(d, "k_R", 0.0), Get(d, "ratio_R", 0.0)}};
    // A given k of 0 has no ratio (DescribeGivenParams gives 0): any fitted
    // noise is off.
    auto off = [&](const Wheel& w) { return w.given <= 0.0 || !(std::abs(w.ratio - 1.0) < negligible); };
    auto factor = [](const Wheel& w) {
      return w.given > 0.0 ? fmt::format("off by x{:.2f}", w.ratio) : std::string("0, but the runs show noise");
    };
    std::string text;
    if (off(wheels[0]) && off(wheels[1])) {
      text = fmt::format(
          "the simulation's wheel noise is {} (left) and {} (right): set k_L = {:.3g}, k_R = {:.3g} m^1/2 (were "
          "{:.3g}, {:.3g})",
          factor(wheels[0]), factor(wheels[1]), wheels[0].fit, wheels[1].fit, given.k_L, given.k_R);
    } else {
      const Wheel& w = off(wheels[0]) ? wheels[0] : wheels[1];
      const Wheel& ok = off(wheels[0]) ? wheels[1] : wheels[0];
      text = fmt::format(
          "the simulation's {} wheel noise is {}: set {} = {:.3g} m^1/2 (was {:.3g}); {} = {:.3g} m^1/2 is "
          "consistent with the runs (fitted x{:.2f}, within the negligible {:.0f} %): keep it",
          w.side, factor(w), w.key, w.fit, w.given, ok.key, ok.given, ok.ratio, 100.0 * negligible);
    }
    for (const Wheel& w : wheels)
      if (off(w)) out.push_back({name, w.key, w.given, w.fit, "m^1/2", text});
  }
  return out;
}

}  // namespace umbmark::diag
