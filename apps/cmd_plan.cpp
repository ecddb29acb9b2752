// `umbmark plan --robot R.toml --kl K --kr K [--noise FIT.json]
//   [--ground-truth mocap|scan|tape] [--gt-sigma-xy S --gt-sigma-theta S]
//   [--target-E_d H] [--target-E_b H] [--target-scale H] [--target-k H]
//   [--max-side M] [--max-time S] [--speed V] [--json FILE] [--motions FILE.json]`:
// the runs to drive for a target precision (lib/planning, docs/plan.md).
// `umbmark plan --check MANIFEST.toml [--kl K --kr K | --noise FIT.json]
//   [--json FILE]`: what a recorded campaign determines, and the smallest
// addition that separates what it confuses.
// The command's logic is api::Plan / api::PlanCheck (lib/api/plan.hpp); this
// file parses, calls them and prints.
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <variant>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "api/plan.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "core/errors.hpp"
#include "planning/check.hpp"
#include "planning/plan.hpp"

namespace umbmark::cli {
namespace {

struct PlanFlags {
  RobotFlags robot;
  std::optional<double> k_L, k_R;
  std::string noise_json;
  std::string ground_truth = "mocap";
  std::optional<double> gt_sigma_xy, gt_sigma_theta;
  std::optional<double> target_E_d, target_E_b, target_scale, target_k;
  double max_side = 3.0;
  std::optional<double> max_time;
  double speed = 0.3, turn_rate = 1.0, pause = 1.0, rate = 20.0;
  JsonFlag json;
  std::string motions;
  std::string check;  ///< --check MANIFEST
};

api::PlanNoise Noise(const PlanFlags& f) { return {f.k_L, f.k_R, f.noise_json}; }

api::PlanTiming Timing(const PlanFlags& f) { return {f.speed, f.turn_rate, f.pause, f.rate}; }

api::RobotSource Robot(const RobotFlags& r) {
  return {r.robot_file, r.wheelbase_m, r.diameter_left_m, r.diameter_right_m, r.ticks_per_rev};
}

void PrintPlan(const planning::PlanResult& r, const planning::PlanOptions& o) {
  const planning::GroundTruthModel gt = o.GroundTruth();
  const planning::PlanDesign& d = r.design;
  fmt::print("Plan for a robot of wheelbase {:.4f} m, wheel noise k_L = {:.3g}, k_R = {:.3g} m^1/2, ground truth {} "
             "({}, {:.2f} mm / {:.2f} mrad)\n",
             o.robot.wheelbase_m, o.noise.k_L, o.noise.k_R, planning::GroundTruthKindToString(o.ground_truth),
             gt.along_path ? "along the path" : "end points only", gt.sigma_xy_m * 1e3, gt.sigma_theta_rad * 1e3);
  fmt::print("  calibrate would recommend {} on it\n", r.method);
  fmt::print("Drive:\n");
  fmt::print("  squares of {:.2f} m: {} cw + {} ccw runs, alternating\n", d.square_side_m, d.runs_cw, d.runs_ccw);
  if (d.back_and_forth_runs > 0)
    fmt::print("  back and forth: {} runs of {:.2f} m out and back\n", d.back_and_forth_runs, d.back_and_forth_length_m);
  for (const auto& p : d.free_paths) fmt::print("  free path: {}\n", p);
  fmt::print("  at {:.2f} m/s and {:.2f} rad/s, {:.1f} s pauses between motions, {:.1f} s standing at each run's start "
             "and end\n",
             o.timing.speed_m_s, o.timing.turn_rate_rad_s, o.timing.pause_s, o.timing.EndPause());
  fmt::print("  driving time {:.0f} s ({:.1f} min)\n", d.time_s, d.time_s / 60.0);
  fmt::print("Predicted 95 % half-widths (the estimate lies this close to the truth in 95 % of campaigns):\n");
  for (const auto& [name, pred, target] : api::PlanQuantities(r.predicted, o)) {
    if (!pred && !target) continue;
    fmt::print("  {:<6} {:>10}  {}{}\n", name, pred ? fmt::format("{:.3g}", *pred) : "undetermined",
               target ? fmt::format("target {:.3g}", *target) : "(not targeted)",
               std::string(name).starts_with(r.binding) && target ? "   <- decides the number of runs" : "");
  }
  for (const auto& n : r.notes) fmt::print("  note: {}\n", n);
  fmt::print("Next: drive it (--motions FILE.json lists the motions), then `umbmark calibrate` and `umbmark plan "
             "--check` on the recording.\n");
}

void PrintCheck(const std::string& manifest, const planning::CheckResult& r) {
  fmt::print("What {} determines ({} cw + {} ccw square runs, {} other runs; ground truth {}, {:.2f} mm / {:.2f} "
             "mrad)\n",
             manifest, r.square_runs_cw, r.square_runs_ccw, r.other_runs,
             r.ground_truth.along_path ? "along the path" : "at the end points", r.ground_truth.sigma_xy_m * 1e3,
             r.ground_truth.sigma_theta_rad * 1e3);
  fmt::print("  calibrate would recommend {}; wheel noise k_L = {:.3g}, k_R = {:.3g} m^1/2{}\n", r.method, r.noise.k_L,
             r.noise.k_R, r.noise_fitted ? " (fitted to these runs)" : "");
  fmt::print("Predicted 95 % half-widths:\n");
  for (const auto& [name, v] : {std::pair{"E_d", r.predicted.E_d}, std::pair{"E_b", r.predicted.E_b},
                                std::pair{"scale", r.predicted.scale}, std::pair{"k_L", r.predicted.k_L},
                                std::pair{"k_R", r.predicted.k_R}})
    fmt::print("  {:<6} {}\n", name, v ? fmt::format("{:.3g}", *v) : "not determined");
  if (r.cannot_separate.empty()) {
    fmt::print("The design separates every parameter and effect checked.\n");
  } else {
    fmt::print("Cannot tell apart:\n");
    for (const auto& c : r.cannot_separate)
      fmt::print("  {}{}\n    add: {}\n", fmt::join(c.what, " / "),
                 c.what.size() == 1 ? " (not excited or not determined)" : fmt::format(" (correlation {:.3f})", c.correlation),
                 c.add);
  }
  for (const auto& n : r.notes) fmt::print("  note: {}\n", n);
}

int RunCheck(const PlanFlags& f) {
  RegisterInputs({f.check}, &f.robot);
  if (!f.noise_json.empty()) CommandOutputs().AddInput(f.noise_json);
  CommandOutputs().AddOutput("--json", f.json.path);
  CommandOutputs().Check();
  if (!f.motions.empty()) throw InvalidOptions("--motions writes a planned design; it does not go with --check");
  api::PlanCheckOptions o;
  o.manifest = f.check;
  o.robot = Robot(f.robot);
  o.noise = Noise(f);
  o.gt_sigma_xy_m = f.gt_sigma_xy;
  o.gt_sigma_theta_rad = f.gt_sigma_theta;
  o.timing = Timing(f);
  const api::PlanCheckResult r = api::PlanCheck(o);
  if (f.json.PrintText()) PrintCheck(f.check, r.check);
  if (!f.json.path.empty()) f.json.EmitAndListOutputs(api::ToJson(r), {});
  return 0;
}

/// --json and --motions are written one after the other: a folder that
/// does not exist is refused before either is written (and before the text),
/// so a failed command leaves no output behind.
void CheckOutputFolders(const std::vector<std::pair<const char*, std::string>>& outputs) {
  for (const auto& [flag, path] : outputs) {
    if (path.empty() || path == "-") continue;
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    std::error_code ec;
    if (!parent.empty() && !std::filesystem::is_directory(parent, ec))
      throw InputError(path, fmt::format("{}: the folder '{}' does not exist; nothing was written", flag,
                                         parent.string()));
  }
}

int RunPlan(const PlanFlags& f) {
  if (!f.check.empty()) return RunCheck(f);
  RegisterInputs(f.noise_json.empty() ? std::vector<std::string>{} : std::vector<std::string>{f.noise_json}, &f.robot);
  CommandOutputs().AddOutput("--json", f.json.path);
  CommandOutputs().AddOutput("--motions", f.motions);
  CommandOutputs().Check();
  CheckOutputFolders({{"--json", f.json.path}, {"--motions", f.motions}});
  api::PlanOptions o;
  o.robot = Robot(f.robot);
  o.noise = Noise(f);
  o.ground_truth = f.ground_truth;
  o.gt_sigma_xy_m = f.gt_sigma_xy;
  o.gt_sigma_theta_rad = f.gt_sigma_theta;
  o.target_E_d = f.target_E_d;
  o.target_E_b = f.target_E_b;
  o.target_scale = f.target_scale;
  o.target_k = f.target_k;
  o.max_side_m = f.max_side;
  o.max_time_s = f.max_time;
  o.timing = Timing(f);
  const api::PlanResult r = api::Plan(o);
  if (f.json.PrintText()) PrintPlan(r.plan, r.options);
  std::vector<std::string> written;
  if (!f.motions.empty()) {
    CommandOutputs().Write(f.motions, api::PlanMotionsJson(r));
    written.push_back(f.motions + " (motions)");
  }
  if (!f.json.path.empty()) {
    f.json.EmitAndListOutputs(api::ToJson(r), written);
  } else {
    PrintWritten(written, true);
  }
  return 0;
}

}  // namespace

Command SetupPlan(CLI::App& parent) {
  auto f = std::make_shared<PlanFlags>();
  auto* app = parent.add_subcommand("plan", "The runs to drive for a target precision of the calibration and noise");
  f->robot.Bind(*app);
  app->add_option("--kl", f->k_L, "Left wheel noise k_L [m^1/2] the plan assumes")->check(NonNegative());
  app->add_option("--kr", f->k_R, "Right wheel noise k_R [m^1/2]")->check(NonNegative());
  app->add_option("--noise", f->noise_json, "k_L, k_R from a `fit-noise --json` file instead of --kl/--kr");
  app->add_option("--ground-truth", f->ground_truth,
                  "Where the ground truth sees the robot: mocap (along the path), scan, tape (end points only)")
      ->check(CLI::IsMember({"mocap", "scan", "tape"}))
      ->capture_default_str();
  app->add_option("--gt-sigma-xy", f->gt_sigma_xy,
                  "Ground truth noise per axis and pose [m] (default mocap 0.0003, scan 0.005, tape 0.002)")
      ->check(NonNegative());
  app->add_option("--gt-sigma-theta", f->gt_sigma_theta,
                  "Ground truth heading noise per pose [rad] (default mocap 0.001, scan and tape 0.005)")
      ->check(NonNegative());
  // The contract's spelling, and the one with '-' that Python's target_E_d
  // keyword becomes (as E_d=... becomes simulate's --E-d).
  app->add_option("--target-E_d,--target-E-d", f->target_E_d, "95 % half-width wanted for E_d (a fraction, e.g. 0.0005)")
      ->check(Positive());
  app->add_option("--target-E_b,--target-E-b", f->target_E_b, "95 % half-width wanted for E_b (a fraction)")
      ->check(Positive());
  app->add_option("--target-scale", f->target_scale, "95 % half-width wanted for the overall scale (a fraction)")
      ->check(Positive());
  app->add_option("--target-k", f->target_k, "95 % half-width wanted for k_L and k_R each [m^1/2]")->check(Positive());
  app->add_option("--max-side", f->max_side, "Free floor space: longest square side and back-and-forth length [m]")
      ->check(Plausible("side_m"))
      ->capture_default_str();
  app->add_option("--max-time", f->max_time, "Driving time allowed [s]")->check(Positive());
  app->add_option("--speed", f->speed, "Driving speed [m/s]")->check(Positive())->capture_default_str();
  app->add_option("--turn-rate", f->turn_rate, "Spot-turn rate [rad/s]")->check(Positive())->capture_default_str();
  app->add_option("--pause", f->pause, "Pause between motions [s]")->check(NonNegative())->capture_default_str();
  app->add_option("--rate", f->rate, "Logging rate of the recording [Hz]")->check(NumberIn(0.1, 10000.0))->capture_default_str();
  f->json.Bind(*app);
  app->add_option("--motions", f->motions, "Write the design as a list of motions (JSON) a robot script can drive");
  app->add_option("--check", f->check,
                  "Instead of planning: what the recorded campaign MANIFEST.toml determines, and what it cannot "
                  "tell apart");
  return {app, [f] { return RunPlan(*f); }};
}

}  // namespace umbmark::cli
