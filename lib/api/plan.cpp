// `plan` and `plan --check` as library calls (see plan.hpp).
#include "api/plan.hpp"

#include <cmath>
#include <tuple>
#include <utility>
#include <variant>

#include <fmt/format.h>

#include "api/json.hpp"
#include "core/errors.hpp"
#include "formats/data_file.hpp"
#include "formats/file_text.hpp"
#include "formats/manifest.hpp"
#include "output/atomic_write.hpp"

namespace umbmark::api {

namespace {

/// k_L, k_R of a `fit-noise --json` file.
WheelNoise NoiseFromJson(const std::string& path) {
  const nlohmann::json j = ReadJsonFile(path);
  auto get = [&](const char* key) {
    if (!j.is_object() || !j.contains(key) || !j[key].is_number())
      throw InputError(path, fmt::format("no number `{}` (expected the JSON of `umbmark fit-noise --json`)", key));
    const double v = j[key].get<double>();
    if (!std::isfinite(v) || v < 0.0) throw InputError(path, fmt::format("`{}` = {} must be a finite number >= 0", key, v));
    return v;
  };
  return {get("k_L"), get("k_R")};
}

/// "" or the message of a noise given both ways, or of a bad k.
std::string CheckNoise(const PlanNoise& n) {
  if (!n.noise_file.empty() && (n.k_L || n.k_R))
    return "give the wheel noise either as --noise FIT.json or as --kl/--kr, not both";
  for (const auto& [name, k] : {std::pair{"--kl", n.k_L}, std::pair{"--kr", n.k_R}})
    if (k && !(std::isfinite(*k) && *k >= 0.0)) return fmt::format("{}: must be a finite number >= 0 (got '{}')", name, *k);
  return {};
}

std::string CheckTiming(const PlanTiming& t) {
  for (const auto& [name, v] : {std::pair{"--speed", t.speed_m_s}, std::pair{"--turn-rate", t.turn_rate_rad_s},
                                std::pair{"--rate", t.rate_hz}})
    if (!(std::isfinite(v) && v > 0.0)) return fmt::format("{}: must be a finite number > 0 (got '{}')", name, v);
  if (!(std::isfinite(t.pause_s) && t.pause_s >= 0.0))
    return fmt::format("--pause: must be a finite number >= 0 (got '{}')", t.pause_s);
  return {};
}

void ApplyTiming(const PlanTiming& t, planning::MotionTiming& timing, double& rate_hz) {
  timing.speed_m_s = t.speed_m_s;
  timing.turn_rate_rad_s = t.turn_rate_rad_s;
  timing.pause_s = t.pause_s;
  rate_hz = t.rate_hz;
}

}  // namespace

std::vector<std::tuple<const char*, std::optional<double>, std::optional<double>>> PlanQuantities(
    const planning::HalfWidths& h, const planning::PlanOptions& o) {
  return {{"E_d", h.E_d, o.target_E_d},
          {"E_b", h.E_b, o.target_E_b},
          {"scale", h.scale, o.target_scale},
          {"k_L", h.k_L, o.target_k},
          {"k_R", h.k_R, o.target_k}};
}

std::string PlanOptions::Check() const {
  if (auto e = robot.Check(); !e.empty()) return e;
  if (auto e = CheckNoise(noise); !e.empty()) return e;
  if (noise.noise_file.empty() && (!noise.k_L || !noise.k_R))
    return "the wheel noise is needed: --kl K --kr K, or --noise FIT.json";
  if (!planning::GroundTruthKindFromString(ground_truth))
    return fmt::format("--ground-truth: '{}' is not one of mocap, scan, tape", ground_truth);
  return CheckTiming(timing);
}

PlanResult Plan(const PlanOptions& options) {
  PlanResult r;
  planning::PlanOptions& o = r.options;
  o.robot = options.robot.Resolve();
  if (auto e = options.Check(); !e.empty()) throw InvalidOptions(e);
  o.noise = options.noise.noise_file.empty() ? WheelNoise{*options.noise.k_L, *options.noise.k_R}
                                             : NoiseFromJson(options.noise.noise_file);
  o.ground_truth = *planning::GroundTruthKindFromString(options.ground_truth);
  o.gt_sigma_xy_m = options.gt_sigma_xy_m;
  o.gt_sigma_theta_rad = options.gt_sigma_theta_rad;
  o.target_E_d = options.target_E_d;
  o.target_E_b = options.target_E_b;
  o.target_scale = options.target_scale;
  o.target_k = options.target_k;
  o.max_side_m = options.max_side_m;
  o.max_time_s = options.max_time_s;
  ApplyTiming(options.timing, o.timing, o.rate_hz);
  if (auto e = o.Check(); !e.empty()) throw InvalidOptions(e);
  r.plan = planning::Plan(o);
  if (!r.plan.ok()) throw QualityGateError("umbmark plan: target cannot be met: " + r.plan.unmet);
  for (const auto& [name, p, target] : PlanQuantities(r.plan.predicted, o)) {
    if (target) {
      r.predicted_ci95[name] = p;
      r.targets[name] = *target;
    } else if (p) {
      r.also_predicted_ci95[name] = *p;
    }
  }
  const planning::GroundTruthModel gt = o.GroundTruth();
  r.design = r.plan.design;
  r.binding = r.plan.binding;
  r.method = r.plan.method;
  r.ground_truth = {planning::GroundTruthKindToString(o.ground_truth), gt.sigma_xy_m, gt.sigma_theta_rad};
  r.k_L = o.noise.k_L;
  r.k_R = o.noise.k_R;
  r.notes = r.plan.notes;
  return r;
}

nlohmann::json ToJson(const PlanResult& r) {
  const planning::PlanDesign& d = r.design;
  nlohmann::json pred = nlohmann::json::object(), other = nlohmann::json::object(), targets = nlohmann::json::object();
  for (const auto& [name, p] : r.predicted_ci95) pred[name] = p ? JsonNumber(*p) : nullptr;
  for (const auto& [name, t] : r.targets) targets[name] = t;
  for (const auto& [name, p] : r.also_predicted_ci95) other[name] = p;
  return {{"design", {{"square_side_m", d.square_side_m},
                      {"runs_cw", d.runs_cw},
                      {"runs_ccw", d.runs_ccw},
                      {"back_and_forth_runs", d.back_and_forth_runs},
                      {"back_and_forth_length_m", d.back_and_forth_length_m},
                      {"free_paths", d.free_paths},
                      {"pause_s", d.pause_s},
                      {"time_s", d.time_s}}},
          {"predicted_ci95", pred},
          {"targets", targets},
          {"also_predicted_ci95", other},
          {"binding", r.binding},
          {"method", r.method},
          {"ground_truth", {{"kind", r.ground_truth.kind},
                            {"sigma_xy_m", r.ground_truth.sigma_xy_m},
                            {"sigma_theta_rad", r.ground_truth.sigma_theta_rad}}},
          {"k_L", r.k_L},
          {"k_R", r.k_R},
          {"notes", r.notes},
          {"warnings", r.warnings}};
}

std::string PlanMotionsJson(const PlanResult& result) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& dm : planning::DesignMotions(result.plan.design, result.options)) {
    const planning::Motion& m = dm.motion;
    nlohmann::json j = {{"kind", planning::MotionKindToString(m.kind)}};
    switch (m.kind) {
      case planning::Motion::Kind::kLine: j["distance_m"] = m.distance_m; j["speed"] = m.speed; break;
      case planning::Motion::Kind::kTurn: j["angle_rad"] = m.angle_rad; j["speed"] = m.speed; break;
      case planning::Motion::Kind::kArc:
        j["radius_m"] = m.radius_m;
        j["angle_rad"] = m.angle_rad;
        j["speed"] = m.speed;
        break;
      case planning::Motion::Kind::kPause: j["duration_s"] = m.duration_s; break;
    }
    j["run"] = dm.run;
    j["experiment"] = planning::RunKindToString(dm.kind);
    out.push_back(j);
  }
  return DumpJson(out) + "\n";
}

void WritePlanMotions(const PlanResult& result, const std::string& path) {
  io::WriteFileAtomically(path, PlanMotionsJson(result));
}

std::string PlanCheckOptions::Check() const {
  if (manifest.empty()) return "--check: the campaign manifest is needed";
  if (!io::IsManifestPath(manifest)) return fmt::format("--check {}: expected a campaign manifest (.toml)", manifest);
  if (auto e = robot.Check(); !e.empty()) return e;
  if (auto e = CheckNoise(noise); !e.empty()) return e;
  if (noise.noise_file.empty() && (noise.k_L || noise.k_R) && !(noise.k_L && noise.k_R)) return "--kl and --kr go together";
  for (const auto& [name, s] : {std::pair{"--gt-sigma-xy", gt_sigma_xy_m}, std::pair{"--gt-sigma-theta", gt_sigma_theta_rad}})
    if (s && !(std::isfinite(*s) && *s >= 0.0)) return fmt::format("{}: must be a finite number >= 0 (got '{}')", name, *s);
  return CheckTiming(timing);
}

PlanCheckResult PlanCheck(const PlanCheckOptions& options) {
  // The manifest is read before the other options are checked (the
  // command line's order of messages).
  if (!options.manifest.empty() && !io::IsManifestPath(options.manifest)) throw InvalidOptions(options.Check());
  const Manifest m = io::ReadManifest(options.manifest);
  const RobotParams robot = options.robot.Resolve(m.robot);
  if (auto e = options.Check(); !e.empty()) throw InvalidOptions(e);
  planning::CheckOptions o;
  if (!options.noise.noise_file.empty()) o.noise = NoiseFromJson(options.noise.noise_file);
  else if (options.noise.k_L) o.noise = WheelNoise{*options.noise.k_L, *options.noise.k_R};
  if (m.ground_truth) o.ground_truth = planning::GroundTruthModel{true, m.ground_truth->sigma_xy_m, m.ground_truth->sigma_theta_rad};
  if (options.gt_sigma_xy_m || options.gt_sigma_theta_rad) {
    planning::GroundTruthModel g = o.ground_truth.value_or(planning::GroundTruthModel{});
    if (options.gt_sigma_xy_m) g.sigma_xy_m = *options.gt_sigma_xy_m;
    if (options.gt_sigma_theta_rad) g.sigma_theta_rad = *options.gt_sigma_theta_rad;
    o.ground_truth = g;
  }
  ApplyTiming(options.timing, o.timing, o.rate_hz);
  std::vector<io::RunFile> files;
  files.reserve(m.experiments.size());
  std::vector<planning::CheckExperiment> experiments;
  for (const auto& e : m.experiments) files.push_back(io::ReadRunFile(e.resolved_file));
  for (std::size_t i = 0; i < m.experiments.size(); ++i) {
    const auto& e = m.experiments[i];
    planning::CheckExperiment x{e.kind, e.side_m, e.distance_m, e.resolved_file, nullptr, nullptr};
    if (auto* t = std::get_if<TrajectoryData>(&files[i])) x.trajectories = t;
    else x.endpoints = &std::get<EndpointData>(files[i]);
    experiments.push_back(x);
  }
  PlanCheckResult r;
  r.check = planning::CheckCampaign(robot, experiments, o);
  const planning::CheckResult& c = r.check;
  r.input = options.manifest;
  for (const auto& [name, v] : {std::pair{"E_d", c.predicted.E_d}, std::pair{"E_b", c.predicted.E_b},
                                std::pair{"scale", c.predicted.scale}, std::pair{"k_L", c.predicted.k_L},
                                std::pair{"k_R", c.predicted.k_R}})
    if (v) r.predicted_ci95[name] = *v;
  for (const auto& x : c.cannot_separate) r.cannot_separate.push_back({x.what, x.kind, x.add, x.correlation});
  r.method = c.method;
  r.k_L = c.noise.k_L;
  r.k_R = c.noise.k_R;
  r.noise_fitted = c.noise_fitted;
  r.calibration_noise = c.calibration_noise;
  r.ground_truth = c.ground_truth;
  r.square_runs_cw = c.square_runs_cw;
  r.square_runs_ccw = c.square_runs_ccw;
  r.other_runs = c.other_runs;
  r.notes = c.notes;
  return r;
}

nlohmann::json ToJson(const PlanCheckResult& r) {
  nlohmann::json pred = nlohmann::json::object(), conf = nlohmann::json::array();
  for (const auto& [name, v] : r.predicted_ci95) pred[name] = JsonNumber(v);
  for (const auto& c : r.cannot_separate)
    conf.push_back({{"what", c.what}, {"kind", c.kind}, {"add", c.add}, {"correlation", c.correlation}});
  return {{"input", r.input},
          {"predicted_ci95", pred},
          {"cannot_separate", conf},
          {"method", r.method},
          {"k_L", r.k_L},
          {"k_R", r.k_R},
          {"noise_fitted", r.noise_fitted},
          {"calibration_noise", {{"k_L", r.calibration_noise.k_L}, {"k_R", r.calibration_noise.k_R}}},
          {"ground_truth", {{"along_path", r.ground_truth.along_path},
                            {"sigma_xy_m", r.ground_truth.sigma_xy_m},
                            {"sigma_theta_rad", r.ground_truth.sigma_theta_rad}}},
          {"square_runs_cw", r.square_runs_cw},
          {"square_runs_ccw", r.square_runs_ccw},
          {"other_runs", r.other_runs},
          {"notes", r.notes},
          {"warnings", r.warnings}};
}

}  // namespace umbmark::api
