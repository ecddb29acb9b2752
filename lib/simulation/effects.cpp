// Effect catalogue, checks and "NAME:k=v,..." parsing (see effects.hpp).
#include "simulation/effects.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <set>

#include <fmt/format.h>

#include "core/errors.hpp"

namespace umbmark::sim {

const std::vector<EffectDescriptor>& EffectCatalogue() {
  static const std::vector<EffectDescriptor> catalogue = {
      {EffectKind::kScaleError, "scale_error", {{"s", &Effects::scale_s, ""}}, true,
       "both true wheel diameters are (1 + s) times the model's"},
      {EffectKind::kTurnScrub, "turn_scrub", {{"k", &Effects::scrub_k, ""}}, true,
       "in on-the-spot turns the true heading change is (1 - k) times what the true wheel travel implies"},
      {EffectKind::kDirectionAsymmetry, "direction_asymmetry", {{"a", &Effects::asymmetry_a, ""}}, true,
       "a wheel turning backwards has (1 + a) times its forward effective diameter"},
      {EffectKind::kCastorKick, "castor_kick", {{"kappa", &Effects::castor_kappa, "rad"}}, true,
       "at every start from standstill the true heading jumps by kappa (forward) or -kappa (backward); spot "
       "turns excluded"},
      {EffectKind::kBumpOutliers,
       "bump_outliers",
       {{"rate", &Effects::bump_rate, "1/m"}, {"sigma", &Effects::bump_sigma, "m"}},
       true,
       "per wheel, Poisson bumps with `rate` per metre of travel, each adding N(0, sigma^2) m of travel"},
      {EffectKind::kCorrelatedNoise, "correlated_noise", {{"rho", &Effects::noise_rho, ""}}, true,
       "left and right random wheel errors have correlation rho"},
      {EffectKind::kParameterDrift, "parameter_drift", {{"r", &Effects::drift_r, "1/run"}}, true,
       "in run i of the campaign the true right wheel diameter is (1 + r i) times run 0's"},
      {EffectKind::kGtOffset,
       "gt_offset",
       {{"dx", &Effects::gt_dx, "m"}, {"dy", &Effects::gt_dy, "m"}},
       true,
       "ground truth reports the point (dx, dy) of the robot frame instead of the axle midpoint"},
      {EffectKind::kTimeOffset, "time_offset", {{"tau", &Effects::time_tau, "s"}}, true,
       "a ground-truth sample stamped t shows the true pose at t - tau"},
      {EffectKind::kStandstillMotion,
       "standstill_motion",
       {{"sigma_xy", &Effects::stand_sigma_xy, "m"}, {"sigma_theta", &Effects::stand_sigma_theta, "rad"}},
       true,
       "after every motion, while the encoders read still, the true pose moves by N(0, sigma_xy^2) m along each "
       "robot axis and N(0, sigma_theta^2) rad in heading, independently per standstill"},
      {EffectKind::kMotionNoiseFloor, "motion_noise_floor", {{"sigma", &Effects::floor_sigma, "m"}}, true,
       "every motion between two standstills adds N(0, sigma^2) m to each wheel's true travel, independently of "
       "its length"},
      {EffectKind::kRunTimeOffset, "run_time_offset", {{"tau_sd", &Effects::run_tau_sd, "s"}}, true,
       "in run i the ground truth stamped t shows the true pose at t - tau_i, tau_i ~ N(0, tau_sd^2) per run"},
      {EffectKind::kStopSlide,
       "stop_slide",
       {{"d", &Effects::slide_d, "s^2/m"},
        {"a", &Effects::slide_a, "s^2/rad"},
        {"arc", &Effects::slide_arc, ""},
        {"back", &Effects::slide_back, ""}},
       true,
       "at every stop after a straight or arc motion at speed v the chassis coasts on along its last direction "
       "of travel by d v^2 m while the encoders read still; after a spot turn at rate w it turns on by a w^2 rad"},
      {EffectKind::kCastorSwivel, "castor_swivel", {{"kappa", &Effects::swivel_kappa, "rad"}}, true,
       "at the start of a straight or arc motion after a spot turn the heading jumps by kappa times the turn's "
       "sign (ccw +1, cw -1); after a reversal of the drive direction by +kappa or -kappa with equal probability"},
      {EffectKind::kGtYawMisalignment, "gt_yaw_misalignment", {{"delta", &Effects::yaw_delta, "rad"}}, false,
       "(outside the contract) ground-truth heading = true heading + delta; position right"},
      {EffectKind::kFloorSlope,
       "floor_slope",
       {{"g", &Effects::slope_g, "m/m"}, {"dir", &Effects::slope_dir, "rad"}},
       false,
       "(outside the contract) the robot slides g metres per metre of wheel travel towards direction dir of "
       "its start frame"},
      {EffectKind::kWheelbaseError, "wheelbase_error", {}, true,
       "(diagnose --baseline) the given model's wheelbase differs from the robot's", false},
      {EffectKind::kDiameterRatioError, "diameter_ratio_error", {}, true,
       "(diagnose --baseline) the given model's wheel-diameter ratio differs from the robot's", false},
      {EffectKind::kWheelNoiseError, "wheel_noise_error", {}, true,
       "(diagnose --baseline) the given wheel noise k_L, k_R differs from the robot's", false},
  };
  return catalogue;
}

std::vector<EffectKind> ContractEffects() {
  std::vector<EffectKind> out;
  for (const auto& d : EffectCatalogue())
    if (d.in_contract && d.simulated) out.push_back(d.kind);
  return out;
}

std::vector<EffectKind> ParameterErrorEffects() {
  return {EffectKind::kWheelbaseError, EffectKind::kDiameterRatioError, EffectKind::kWheelNoiseError};
}

bool IsParameterError(EffectKind kind) { return !Describe(kind).simulated; }

const EffectDescriptor& Describe(EffectKind kind) {
  for (const auto& d : EffectCatalogue())
    if (d.kind == kind) return d;
  return EffectCatalogue().front();  // unreachable: every kind is catalogued
}

const char* EffectToString(EffectKind kind) { return Describe(kind).name.data(); }

std::optional<EffectKind> EffectFromString(std::string_view name) {
  for (const auto& d : EffectCatalogue())
    if (d.name == name) return d.kind;
  return std::nullopt;
}

namespace {
// Ranges of the issue-21 effects: d = 1/(2 mu g) <= 1 s^2/m is a friction
// coefficient of at least 0.05 (ice is about 0.05-0.1); a the same for the
// turn; a swivel castor's kick of at most 0.5 rad (29 deg).
constexpr double kMaxSlideD = 1.0;
constexpr double kMaxSlideA = 1.0;
constexpr double kMaxSwivelKappa = 0.5;
// stop_slide's shape (diagnosis.md, "A slide's shape"): arc 0-4 (2 is two
// locked wheels sliding forward), a backward coast 0.1-5 times the forward.
constexpr double kMaxSlideArc = 4.0;
constexpr double kMinSlideBack = -0.9, kMaxSlideBack = 4.0;
}  // namespace

std::string Effects::Check() const {
  // Ranges that also catch NaN (the message gives the allowed range).
  if (!(slide_d >= 0.0 && slide_d <= kMaxSlideD))
    return fmt::format("stop_slide.d = {} must be in [0, {}] s^2/m (d = 1/(2 mu g): a friction coefficient mu of at "
                       "least 0.05)",
                       slide_d, kMaxSlideD);
  if (!(slide_a >= 0.0 && slide_a <= kMaxSlideA))
    return fmt::format("stop_slide.a = {} must be in [0, {}] s^2/rad", slide_a, kMaxSlideA);
  if (!(slide_arc >= 0.0 && slide_arc <= kMaxSlideArc))
    return fmt::format("stop_slide.arc = {} must be in [0, {}] (2: the heading keeps turning at the arc's rate "
                       "through the coast)",
                       slide_arc, kMaxSlideArc);
  if (!(slide_back >= kMinSlideBack && slide_back <= kMaxSlideBack))
    return fmt::format("stop_slide.back = {} must be in [{}, {}] (a backward coast (1 + back) times as long)",
                       slide_back, kMinSlideBack, kMaxSlideBack);
  if (!(std::abs(swivel_kappa) <= kMaxSwivelKappa))
    return fmt::format("castor_swivel.kappa = {} must be in [-{}, {}] rad", swivel_kappa, kMaxSwivelKappa,
                       kMaxSwivelKappa);
  auto finite = [](const char* name, double v) -> std::string {
    if (!std::isfinite(v)) return fmt::format("{} = {} must be finite", name, v);
    return {};
  };
  for (const auto& d : EffectCatalogue()) {
    for (const auto& p : d.parameters) {
      const std::string full = fmt::format("{}.{}", d.name, p.name);
      if (auto e = finite(full.c_str(), this->*p.field); !e.empty()) return e;
    }
  }
  if (!(scale_s > -0.5 && scale_s < 0.5)) return fmt::format("scale_error.s = {} must be in (-0.5, 0.5)", scale_s);
  if (!(scrub_k > -0.5 && scrub_k < 0.5)) return fmt::format("turn_scrub.k = {} must be in (-0.5, 0.5)", scrub_k);
  if (!(asymmetry_a > -0.5 && asymmetry_a < 0.5))
    return fmt::format("direction_asymmetry.a = {} must be in (-0.5, 0.5)", asymmetry_a);
  if (!(std::abs(castor_kappa) < 0.5)) return fmt::format("castor_kick.kappa = {} must be in (-0.5, 0.5) rad", castor_kappa);
  if (bump_rate < 0.0) return fmt::format("bump_outliers.rate = {} must be >= 0", bump_rate);
  if (bump_sigma < 0.0) return fmt::format("bump_outliers.sigma = {} must be >= 0", bump_sigma);
  if (bump_rate > 1000.0) return fmt::format("bump_outliers.rate = {} must be <= 1000 per metre", bump_rate);
  if (!(std::abs(noise_rho) <= 1.0)) return fmt::format("correlated_noise.rho = {} must be in [-1, 1]", noise_rho);
  if (!(std::abs(drift_r) < 0.1)) return fmt::format("parameter_drift.r = {} must be in (-0.1, 0.1)", drift_r);
  if (!(std::abs(gt_dx) < 10.0 && std::abs(gt_dy) < 10.0))
    return fmt::format("gt_offset (dx, dy) = ({}, {}) must be within 10 m", gt_dx, gt_dy);
  if (!(std::abs(time_tau) < 10.0)) return fmt::format("time_offset.tau = {} must be in (-10, 10) s", time_tau);
  if (!(stand_sigma_xy >= 0.0 && stand_sigma_xy < 1.0))
    return fmt::format("standstill_motion.sigma_xy = {} must be in [0, 1) m", stand_sigma_xy);
  if (!(stand_sigma_theta >= 0.0 && stand_sigma_theta < 0.5))
    return fmt::format("standstill_motion.sigma_theta = {} must be in [0, 0.5) rad", stand_sigma_theta);
  if (!(floor_sigma >= 0.0 && floor_sigma < 1.0))
    return fmt::format("motion_noise_floor.sigma = {} must be in [0, 1) m", floor_sigma);
  if (!(run_tau_sd >= 0.0 && run_tau_sd < 10.0))
    return fmt::format("run_time_offset.tau_sd = {} must be in [0, 10) s", run_tau_sd);
  if (!(std::abs(yaw_delta) < 1.0))
    return fmt::format("gt_yaw_misalignment.delta = {} must be in (-1, 1) rad", yaw_delta);
  if (!(slope_g >= 0.0 && slope_g < 0.5)) return fmt::format("floor_slope.g = {} must be in [0, 0.5)", slope_g);
  return {};
}

bool Effects::Active(EffectKind kind) const {
  const EffectDescriptor& d = Describe(kind);
  if (kind == EffectKind::kBumpOutliers) return bump_rate > 0.0 && bump_sigma > 0.0;
  if (kind == EffectKind::kFloorSlope) return slope_g > 0.0;
  for (const auto& p : d.parameters)
    if (this->*p.field != 0.0) return true;
  return false;
}

std::vector<EffectKind> Effects::ActiveKinds() const {
  std::vector<EffectKind> out;
  for (const auto& d : EffectCatalogue())
    if (Active(d.kind)) out.push_back(d.kind);
  return out;
}

void ParseEffectSpec(std::string_view spec, Effects& effects) {
  const auto fail = [&](const std::string& what) {
    throw InvalidOptions(fmt::format("--effect '{}': {}", spec, what));
  };
  const std::size_t colon = spec.find(':');
  const std::string_view name = spec.substr(0, colon);
  const auto kind = EffectFromString(name);
  if (!kind) {
    std::string known;
    for (const auto& d : EffectCatalogue()) known += (known.empty() ? "" : ", ") + std::string(d.name);
    fail(fmt::format("unknown effect '{}' (known: {})", name, known));
  }
  const EffectDescriptor& d = Describe(*kind);
  if (!d.simulated)
    fail(fmt::format("'{}' is a parameter error that `diagnose --baseline` names, not an effect the simulator "
                     "produces: simulate the robot with other parameters instead (E_d, E_b, k_L, k_R)",
                     d.name));
  if (colon == std::string_view::npos || colon + 1 >= spec.size())
    fail(fmt::format("no parameters; expected {}:{}=VALUE,...", d.name, d.parameters.front().name));
  std::string_view rest = spec.substr(colon + 1);
  std::set<std::string_view> seen;
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos) fail(fmt::format("'{}' is not KEY=VALUE", item));
    const std::string_view key = item.substr(0, eq), value = item.substr(eq + 1);
    const EffectParameter* param = nullptr;
    for (const auto& p : d.parameters)
      if (p.name == key) param = &p;
    if (param == nullptr) {
      std::string known;
      for (const auto& p : d.parameters) known += (known.empty() ? "" : ", ") + std::string(p.name);
      fail(fmt::format("{} has no parameter '{}' (its parameters: {})", d.name, key, known));
    }
    if (!seen.insert(key).second) fail(fmt::format("parameter '{}' given twice", key));
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
    if (ec != std::errc() || ptr != value.data() + value.size() || !std::isfinite(v)) {
      // The allowed range, where Check states one that NaN fails.
      Effects probe;
      probe.*(param->field) = std::numeric_limits<double>::quiet_NaN();
      const std::string range = probe.Check();
      const std::size_t must = range.find(" must be ");
      fail(fmt::format("{} = '{}' is not a finite number{}", key, value,
                       range.starts_with(fmt::format("{}.{} ", d.name, key)) && must != std::string::npos &&
                               range.find("must be finite") == std::string::npos
                           ? ";" + range.substr(must)
                           : std::string()));
    }
    effects.*(param->field) = v;
  }
  if (seen.empty()) fail("no parameters");
  // The effect's own range (the rest of Check is the caller's business).
  if (const std::string e = effects.Check(); e.starts_with(std::string(d.name) + ".")) fail(e);
}

std::string EffectSpecString(EffectKind kind, const Effects& effects) {
  const EffectDescriptor& d = Describe(kind);
  std::string out(d.name);
  char sep = ':';
  for (const auto& p : d.parameters) {
    out += fmt::format("{}{}={}", sep, p.name, effects.*(p.field));
    sep = ',';
  }
  return out;
}

}  // namespace umbmark::sim
