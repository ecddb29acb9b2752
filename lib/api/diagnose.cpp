// `umbmark diagnose` as a library call (see diagnose.hpp).
#include "api/diagnose.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <variant>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "diagnosis/design_check.hpp"
#include "diagnosis/pieces.hpp"
#include "evaluation/data_warnings.hpp"
#include "formats/file_text.hpp"
#include "formats/manifest.hpp"
#include "formats/params_json.hpp"
#include "simulation/effects.hpp"

namespace umbmark::api {

namespace {

/// A --baseline whose wheelbase or a wheel diameter differs from the
/// campaign's recorded one by more than this (relative) is another robot's
/// (UMBmark corrections of a real robot are a few per cent at most).
constexpr double kOtherRobotRelative = 0.10;

/// Refuses (InputError, exit 1) a --baseline that belongs to another robot
/// than the campaign's, unless --baseline-other-robot: its parameters lie
/// more than kOtherRobotRelative from the campaign's recorded ones, or its
/// own `recorded_parameters` (the robot file it was calibrated from) differ
/// from the campaign's while its result is not the campaign's robot either
/// (a second pass on a compensated robot records the corrected parameters:
/// accepted).
void CheckBaselineRobot(const std::string& path, const RobotParams& given, const RobotParams& campaign) {
  const auto rel = [](double a, double b) { return std::abs(a / b - 1.0); };
  const auto largest = [&](const RobotParams& a) {
    return std::max({rel(a.wheelbase_m, campaign.wheelbase_m), rel(a.wheel_diameter_left_m, campaign.wheel_diameter_left_m),
                     rel(a.wheel_diameter_right_m, campaign.wheel_diameter_right_m)});
  };
  const auto describe = [](const RobotParams& p) {
    return fmt::format("wheelbase {:.6g} m, wheel diameters {:.6g} / {:.6g} m", p.wheelbase_m, p.wheel_diameter_left_m,
                       p.wheel_diameter_right_m);
  };
  const std::string hint = "compare a robot with its own calibration or simulation, or give --baseline-other-robot "
                           "to compare with this one on purpose";
  if (largest(given) > kOtherRobotRelative) {
    throw InputError(path, fmt::format("--baseline is another robot's: its parameters ({}) differ by {:.1f} % from "
                                       "the campaign's recorded robot ({}), more than the {:.0f} % a calibration "
                                       "corrects; {}",
                                       describe(given), 100.0 * largest(given), describe(campaign),
                                       100.0 * kOtherRobotRelative, hint));
  }
  nlohmann::json j = io::ParseJsonDocument(io::ReadWholeFile(path), path);
  if (j.is_object() && j.contains("results") && j["results"].is_array() && j["results"].size() == 1) j = j["results"][0];
  if (!j.is_object() || !j.contains("recorded_parameters")) return;  // a hand-written simulation model
  const nlohmann::json& r = j["recorded_parameters"];
  RobotParams recorded = campaign;
  for (auto [key, field] : {std::pair{"wheelbase_m", &recorded.wheelbase_m},
                            std::pair{"wheel_diameter_left_m", &recorded.wheel_diameter_left_m},
                            std::pair{"wheel_diameter_right_m", &recorded.wheel_diameter_right_m}}) {
    if (r.is_object() && r.contains(key) && r[key].is_number()) *field = r[key].get<double>();
  }
  constexpr double kSame = 1e-6;
  if (largest(recorded) <= kSame || largest(given) <= kSame) return;
  throw InputError(path, fmt::format("--baseline was calibrated from another robot's runs: its recorded_parameters "
                                     "({}) are not the campaign's recorded robot ({}); {}",
                                     describe(recorded), describe(campaign), hint));
}

/// Degenerate data (evaluation/data_warnings.hpp), per file: trajectories
/// and return errors.
std::vector<std::string> DataWarnings(const diag::CampaignData& campaign) {
  std::vector<std::string> warnings;
  for (const auto& file : campaign.files) {
    if (const auto* t = std::get_if<TrajectoryData>(&file)) {
      TrajectoryDataCheck check(campaign.robot);
      for (const auto& run : t->runs) check.Add(run);
      for (auto& w : check.Warnings(t->path)) warnings.push_back(std::move(w));
    } else if (const auto* e = std::get_if<EndpointData>(&file)) {
      EndpointDataCheck check;
      for (const auto& run : e->runs) check.Add(run);
      for (auto& w : check.Warnings(e->path)) warnings.push_back(std::move(w));
    }
  }
  return warnings;
}

}  // namespace

namespace {

std::string In(const char* flag, double v, double lo, double hi) {
  if (std::isfinite(v) && v >= lo && v <= hi) return {};
  return fmt::format("{}: must be a number from {:g} to {:g} (got '{}')", flag, lo, hi, v);
}

std::string NonNegative(const char* flag, double v) {
  if (std::isfinite(v) && v >= 0.0) return {};
  return fmt::format("{}: must be a finite number >= 0 (got '{}')", flag, v);
}

}  // namespace

std::string DiagnoseOptions::Check() const {
  if (manifest.empty()) return "MANIFEST is required";
  for (const std::string& e :
       {In("--null-sims", diag.null_simulations, 20, 1000000), In("--alpha", diag.alpha, 1e-6, 0.5),
        In("--min-heldout-shrink", diag.min_heldout_shrink, 0.01, 1.0),
        NonNegative("--penalty", diag.complexity_penalty_nats), NonNegative("--decisive", diag.decisive_nats),
        In("--folds", diag.pieces.folds, 2, 100),
        In("--piece-length", diag.pieces.max_piece_length_m, 0.01, 1000.0), NonNegative("--negligible", diag.negligible),
        In("--max-effects", diag.max_explanation_effects, 1, 12), In("--threads", diag.threads, 1, 256),
        NonNegative("--where", diag.where_top)}) {
    if (!e.empty()) return e;
  }
  for (const auto& name : effects)
    if (!sim::EffectFromString(name)) return fmt::format("--effects: unknown effect '{}'", name);
  // --kl / --kr: both or neither, finite, >= 0, not both 0; only with --baseline.
  if ((k_L || k_R) && baseline.empty())
    return "--kl/--kr give the wheel noise of a model given by --baseline CAL.json; without --baseline the noise is "
           "fitted to the runs";
  if (k_L.has_value() != k_R.has_value())
    return fmt::format("{} given without {}: give both wheels' noise k_L and k_R [m^1/2] (or neither, and it is "
                       "fitted)",
                       k_L ? "--kl" : "--kr", k_L ? "--kr" : "--kl");
  for (const auto& [flag, v] : {std::pair{"--kl", k_L}, std::pair{"--kr", k_R}})
    if (v && !(std::isfinite(*v) && *v >= 0.0))
      return fmt::format("{} = {} must be a finite wheel noise >= 0 [m^1/2]", flag, *v);
  if (k_L && *k_L == 0.0 && *k_R == 0.0)
    return "--kl and --kr are both 0: a model without wheel noise cannot be compared with real runs";
  if (baseline_other_robot && baseline.empty()) return "--baseline-other-robot requires --baseline";
  return {};
}

DiagnoseResult Diagnose(const DiagnoseOptions& o) {
  if (std::string err = o.Check(); !err.empty()) throw InvalidOptions(err);
  diag::DiagnoseOptions d = o.diag;
  for (const auto& name : o.effects) d.effects.push_back(*sim::EffectFromString(name));
  // A design that cannot determine the baseline is refused before fitting.
  if (const std::string why = diag::CampaignDesignProblem(io::ReadManifest(o.manifest)); !why.empty()) {
    throw InputError(o.manifest, why);
  }
  const diag::CampaignData campaign = diag::LoadCampaign(o.manifest, d.pieces);
  DiagnoseResult r;
  r.manifest = o.manifest;
  r.data_warnings = DataWarnings(campaign);
  if (!o.baseline.empty()) {
    diag::GivenModel g;
    g.params = io::ReadParamsJson(o.baseline, campaign.robot);
    if (!o.baseline_other_robot) CheckBaselineRobot(o.baseline, g.params, campaign.robot);
    g.source = o.baseline;
    g.noise_given = o.k_L.has_value();
    g.k_L = o.k_L.value_or(0.0);
    g.k_R = o.k_R.value_or(0.0);
    d.given = g;
  }
  d.progress = o.progress;
  r.summary = diag::Diagnose(campaign, d);
  return r;
}

nlohmann::json ToJson(const DiagnoseResult& r) {
  nlohmann::json j = diag::DiagnoseToJson(r.summary);
  if (!r.data_warnings.empty()) {
    nlohmann::json all = j.value("warnings", nlohmann::json::array());
    for (const auto& w : r.data_warnings) all.push_back(w);
    j["warnings"] = all;
  }
  j["manifest"] = r.manifest;
  return j;
}

}  // namespace umbmark::api
