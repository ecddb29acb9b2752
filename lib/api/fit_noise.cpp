// `fit-noise` as a library call (see fit_noise.hpp).
#include "api/fit_noise.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <tuple>
#include <variant>

#include <fmt/format.h>

#include "api/fit_noise_report.hpp"
#include "api/json.hpp"
#include "core/errors.hpp"
#include "formats/data_file.hpp"
#include "formats/file_text.hpp"
#include "formats/manifest.hpp"
#include "formats/ros2_params.hpp"

namespace umbmark::api {

namespace {

/// The calibrated robot of a `calibrate --json` file: what --ros2 used
/// (outputs_use), else the refined result, else the classic one.
RobotParams CalibratedRobot(const std::string& path) {
  const nlohmann::json j = ReadJsonFile(path);
  const nlohmann::json* p = nullptr;
  if (j.contains("outputs_use") && j["outputs_use"].contains("parameters")) p = &j["outputs_use"]["parameters"];
  else if (j.contains("refined") && j["refined"].contains("parameters")) p = &j["refined"]["parameters"];
  else if (j.contains("parameters")) p = &j["parameters"];
  if (!p) throw InputError(path, "no `parameters` object (expected the JSON of `umbmark calibrate --json`)");
  RobotParams r;
  try {
    r.wheelbase_m = p->at("wheelbase_m").get<double>();
    r.wheel_diameter_left_m = p->at("wheel_diameter_left_m").get<double>();
    r.wheel_diameter_right_m = p->at("wheel_diameter_right_m").get<double>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, fmt::format("parameters: {}", e.what()));
  }
  if (!(r.wheelbase_m > 0.0) || !(r.wheel_diameter_left_m > 0.0) || !(r.wheel_diameter_right_m > 0.0))
    throw InputError(path, "parameters must be positive");
  return r;
}

struct Loaded {
  std::vector<WheelNoiseFitRun> runs;
  std::vector<std::string> sources;
  int skipped = 0;
  double sigma_xy = 0.0, sigma_theta = 0.0;
  std::optional<double> wheelbase_m;  ///< of the (last) robot read, for --ros2
  bool ground_truth = false;  ///< trajectories or a manifest: the errors come from a ground-truth system
  SystematicErrors systematic;  ///< what the runs were built with (last input)
};

NoiseFitInputOptions InputOptions(const FitNoiseOptions& o, const std::optional<GroundTruthNoise>& manifest_gt,
                                  const RobotParams& robot, const SystematicErrors& estimated) {
  NoiseFitInputOptions in;
  in.second_order = !o.first_order;
  in.systematic = estimated;
  if (!o.params_file.empty()) {
    const RobotParams cal = CalibratedRobot(o.params_file);
    in.systematic = {cal.wheelbase_m / robot.wheelbase_m, cal.wheel_diameter_left_m / robot.wheel_diameter_left_m,
                     cal.wheel_diameter_right_m / robot.wheel_diameter_right_m};
  }
  if (!o.meas_sigma.empty()) {
    in.sigma_xy_m = o.meas_sigma[0];
    in.sigma_theta_rad = o.meas_sigma.size() > 1 ? o.meas_sigma[1] : 0.0;
  } else if (manifest_gt) {
    in.sigma_xy_m = manifest_gt->sigma_xy_m;
    in.sigma_theta_rad = manifest_gt->sigma_theta_rad;
  }
  return in;
}

/// Every run of a trajectory file with ground truth at its start and end.
/// Appends runs of the file that becomes the next entry of out.sources.
void AppendRuns(std::vector<WheelNoiseFitRun> runs, Loaded& out) {
  const int source = static_cast<int>(out.sources.size());
  for (WheelNoiseFitRun& r : runs) r.source = source;
  if (out.runs.empty()) {
    out.runs = std::move(runs);
    return;
  }
  out.runs.reserve(out.runs.size() + runs.size());
  std::move(runs.begin(), runs.end(), std::back_inserter(out.runs));
}

/// Every run of a trajectory file with ground truth at its start and end,
/// read run by run (memory: the fit runs, not the file's samples). The
/// runs are gathered in blocks and moved into one vector of the final size
/// (growing one vector would hold 1.5 times the runs while it reallocates).
void AppendTrajectoryRuns(io::TrajectoryReader& reader, const RobotParams& robot, const std::string& prefix,
                          const NoiseFitInputOptions& in, Loaded& out) {
  constexpr std::size_t kBlock = 1 << 15;
  std::vector<std::vector<WheelNoiseFitRun>> blocks;
  std::size_t total = 0;
  TrajectoryRun run;
  while (reader.NextRun(run)) {
    std::optional<WheelNoiseFitRun> f = NoiseRunFromTrajectory(run, reader.path(), robot, prefix, in);
    if (!f) {
      ++out.skipped;
      continue;
    }
    if (blocks.empty() || blocks.back().size() == kBlock) {
      blocks.emplace_back();
      blocks.back().reserve(kBlock);
    }
    blocks.back().push_back(std::move(*f));
    ++total;
  }
  std::vector<WheelNoiseFitRun> runs;
  runs.reserve(total);
  for (auto& b : blocks) {
    std::move(b.begin(), b.end(), std::back_inserter(runs));
    std::vector<WheelNoiseFitRun>().swap(b);
  }
  AppendRuns(std::move(runs), out);
}

void AppendManifest(const std::string& path, const FitNoiseOptions& o, const SystematicErrors& sys, Loaded& out) {
  const Manifest m = io::ReadManifest(path);
  const RobotParams robot = o.robot.Resolve(m.robot);
  out.wheelbase_m = robot.wheelbase_m;
  const NoiseFitInputOptions in = InputOptions(o, m.ground_truth, robot, sys);
  out.ground_truth = true;
  out.systematic = in.systematic;
  out.sigma_xy = in.sigma_xy_m;
  out.sigma_theta = in.sigma_theta_rad;
  int index = 0;
  for (const Experiment& e : m.experiments) {
    ++index;
    const std::string prefix = fmt::format("exp{}:{}:", index, ExperimentKindToString(e.kind));
    io::OpenedRunFile rf = io::OpenRunFile(e.resolved_file);
    if (auto* t = std::get_if<io::TrajectoryReader>(&rf)) {
      AppendTrajectoryRuns(*t, robot, prefix, in, out);
    } else {
      const auto& ep = std::get<EndpointData>(rf);
      if (e.kind == ExperimentKind::kBackAndForth) {
        AppendRuns(NoiseRunsFromEndpoints(ep, BackAndForthPath(e.distance_m), robot.wheelbase_m, prefix, in), out);
      } else if (e.kind == ExperimentKind::kSquare) {
        for (const bool cw : {true, false}) {  // one path per direction
          EndpointData part{ep.path, {}};
          for (const auto& r : ep.runs) {
            if (r.direction != "cw" && r.direction != "ccw")
              throw InputError(ep.path, r.line, 0, fmt::format("square run direction '{}' must be cw or ccw", r.direction));
            if ((r.direction == "cw") == cw) part.runs.push_back(r);
          }
          AppendRuns(NoiseRunsFromEndpoints(part, SquarePath(e.side_m, cw), robot.wheelbase_m, prefix, in), out);
        }
      } else {
        throw InputError(e.resolved_file, "a 'free' experiment needs a trajectory CSV (its path comes from the ticks)");
      }
    }
    out.sources.push_back(e.resolved_file);
  }
}

Loaded Load(const FitNoiseOptions& o, const SystematicErrors& sys = {}) {
  Loaded out;
  for (const std::string& path : o.inputs) {
    if (io::IsManifestPath(path)) {
      AppendManifest(path, o, sys, out);
      continue;
    }
    const RobotParams robot = o.robot.Resolve();
    out.wheelbase_m = robot.wheelbase_m;
    const NoiseFitInputOptions in = InputOptions(o, std::nullopt, robot, sys);
    out.systematic = in.systematic;
    out.sigma_xy = in.sigma_xy_m;
    out.sigma_theta = in.sigma_theta_rad;
    const std::string prefix = o.inputs.size() > 1 ? path + ":" : "";
    io::OpenedRunFile rf = io::OpenRunFile(path);
    if (auto* t = std::get_if<io::TrajectoryReader>(&rf)) {
      AppendTrajectoryRuns(*t, robot, prefix, in, out);
      out.ground_truth = true;
    } else {
      if (!o.distance_m)
        throw InvalidOptions(path + " holds endpoint errors: give --distance D (each run drove D forward, then D back)");
      AppendRuns(NoiseRunsFromEndpoints(std::get<EndpointData>(rf), BackAndForthPath(*o.distance_m),
                                        robot.wheelbase_m, prefix, in),
                 out);
    }
    out.sources.push_back(path);
  }
  MergeLoneTurnGroups(out.runs);
  return out;
}

/// Step 2: k_L, k_R with the systematic errors estimated jointly (default),
/// given by --params, or none (a calibrated robot).
FitNoiseResult Fit(const FitNoiseOptions& o, Loaded& data) {
  WheelNoiseFitOptions fo;
  fo.restricted = !o.ml;
  fo.sources = data.sources;
  FitNoiseResult f;
  if (!o.params_file.empty()) {
    f.systematic_errors.source = "params";
  } else {
    f.systematic_errors.source = o.systematic == "none" ? "none" : "estimated";
  }
  f.systematic_errors.used = data.systematic;
  if (o.progress) fo.progress = o.progress(fmt::format("fitting k_L, k_R to {} runs", data.runs.size()));
  if (f.systematic_errors.source == "estimated") {
    // The joint fit rebuilds the runs' bases in place (the data are read once).
    SystematicEstimate e;
    f.fit = FitWheelNoiseWithSystematics(data.runs, fo, &e);
    f.systematic_errors.estimate = e;
    f.systematic_errors.used = e.value;
  } else {
    f.fit = FitWheelNoise(data.runs, fo);
  }
  // k at its boundary 0: the data bound it from above only.
  auto determined = [](double k, const std::array<double, 2>& ci) { return !(ci[0] <= 0.0 && k < 0.01 * ci[1]); };
  f.k_L_determined = determined(f.fit.k_L, f.fit.k_L_ci);
  f.k_R_determined = determined(f.fit.k_R, f.fit.k_R_ci);
  return f;
}

std::vector<std::string> Warnings(const Loaded& data, const FitNoiseResult& f) {
  std::vector<std::string> warnings;
  if (data.ground_truth && data.sigma_xy == 0.0 && data.sigma_theta == 0.0) {
    warnings.push_back(
        "the reference noise is 0 although the return errors come from a ground-truth system: its noise is then read "
        "as wheel noise and k comes out high; give --meas-sigma SXY,STHETA (or the manifest's [ground_truth])");
  }
  if (f.systematic_errors.estimate && !f.systematic_errors.estimate->E_d_determined) {
    warnings.push_back(fmt::format(
        "the scatter pulled E_d more than {} from the value the group means give, so E_d was kept at {:.5f}: the "
        "noise model does not fit these runs well (see the goodness of fit) or the design does not show E_d; give "
        "--params CAL.json from `umbmark calibrate` (or --systematic none for a calibrated robot)",
        kMaxJointEdShift, f.systematic_errors.used.c_R / f.systematic_errors.used.c_L));
  }
  if (!f.k_L_determined) warnings.push_back(UndeterminedK(f, "k_L"));
  if (!f.k_R_determined) warnings.push_back(UndeterminedK(f, "k_R"));
  return warnings;
}

/// What the reader should know about the systematic errors' estimate
/// (text, JSON `notes`, HTML).
std::vector<std::string> Notes(const FitNoiseResult& f) {
  std::vector<std::string> notes;
  if (!f.systematic_errors.estimate) return notes;
  if (f.systematic_errors.estimate->E_d_determined && f.systematic_errors.estimate->E_d_se > 0.5 * WheelNoiseFitOptions{}.E_d_prior_sigma)
    notes.push_back(fmt::format("the scatter of this design barely shows E_d (+- {:.4f}, near the prior's {}); the "
                                "intervals include that uncertainty: give --params CAL.json for narrower ones",
                                f.systematic_errors.estimate->E_d_se, WheelNoiseFitOptions{}.E_d_prior_sigma));
  if (!f.systematic_errors.estimate->E_b_determined) {
    const std::string why =
        f.systematic_errors.estimate->turns
            ? fmt::format("the runs' mean return errors determine E_b only to +- {:.3f} (the prior's 0.05: too few "
                          "runs per direction, or too much scatter, for the turns to show it)",
                          f.systematic_errors.estimate->E_b_se)
            : std::string("this design (no turns) does not show E_b");
    notes.push_back(why + "; k is relative to the recorded wheelbase (a wheelbase off by x % moves k by up to x %): "
                          "give --params CAL.json from `umbmark calibrate`");
  }
  return notes;
}

/// The k_L, k_R that --ros2 turns into a covariance. A k at its boundary 0
/// (not determined) would give a covariance that trusts that wheel almost
/// perfectly (4e-10 m^2 pose variance on the README's square campaign), so
/// an undetermined k is replaced by its 95 % upper bound (a conservative
/// covariance; said in the YAML comment and the warnings).
struct Ros2Noise {
  double k_L = 0.0, k_R = 0.0;
  std::string kL_source = "estimate", kR_source = "estimate";  ///< "estimate" or "upper95"
  std::vector<std::string> comments;                           ///< YAML comment lines
};

/// An upper bound above this [m^1/2] says nothing about a wheel: its travel
/// error after 1 m would be 5 cm, 10 to 100 times the k of Chong & Kleeman's
/// robot (4e-4 to 6e-4) and of the robots in data/ (up to 8e-3).
constexpr double kMaxUsefulKBound = 0.05;

/// Ros2Noise of a fit; throws QualityGateError (exit 3, before anything is
/// written) when an undetermined k has no useful upper bound either.
Ros2Noise Ros2NoiseOf(const FitNoiseOptions& o, const FitNoiseResult& f) {
  Ros2Noise r{f.fit.k_L, f.fit.k_R, "estimate", "estimate", {}};
  for (const auto& [name, determined, upper, k, source] :
       {std::tuple{"k_L", f.k_L_determined, f.fit.k_L_ci[1], &r.k_L, &r.kL_source},
        std::tuple{"k_R", f.k_R_determined, f.fit.k_R_ci[1], &r.k_R, &r.kR_source}}) {
    if (determined) continue;
    if (!(upper <= kMaxUsefulKBound))
      throw QualityGateError(fmt::format(
          "fit-noise --ros2 {}: {} is not determined by these {} runs ({}), so no covariance is written; drive more "
          "runs (back-and-forth runs, 10 m forward and back, 20 or more, determine both k), give the reference's "
          "noise with --meas-sigma SXY,STHETA (or the manifest's [ground_truth]){}",
          o.ros2_file, name, f.fit.runs,
          std::isfinite(upper) ? fmt::format("its 95 % upper bound {:.3g} m^1/2 says nothing about a wheel", upper)
                               : std::string("not even bounded from above"),
          f.systematic_errors.source == "estimated"
              ? ", or give the calibration (--params CAL.json from `umbmark calibrate --json`) so that E_d is not "
                "estimated from the same few runs"
              : ""));
    *k = upper;
    *source = "upper95";
    r.comments.push_back(fmt::format("{} is not determined by the runs (its estimate sits at 0): its 95 % upper bound "
                                     "{:.4g} m^1/2 is used, so this covariance is conservative",
                                     name, upper));
  }
  return r;
}

/// The warning --ros2 adds for each k it replaced by its upper bound.
std::vector<std::string> Ros2Warnings(const FitNoiseOptions& o, const FitNoiseResult& f) {
  std::vector<std::string> out;
  if (o.ros2_file.empty()) return out;
  const Ros2Noise k = Ros2NoiseOf(o, f);
  for (const auto& [name, source, value] :
       {std::tuple{"k_L", k.kL_source, k.k_L}, std::tuple{"k_R", k.kR_source, k.k_R}})
    if (source == "upper95")
      out.push_back(fmt::format("--ros2 {}: {} is not determined, so its 95 % upper bound {:.4g} m^1/2 is written "
                                "(a conservative covariance; back-and-forth runs and --meas-sigma would determine it)",
                                o.ros2_file, name, value));
  return out;
}

// diff_drive_controller covariance diagonals from the fitted noise (an
// undetermined k at its 95 % upper bound, Ros2Noise), and the YAML text.
FitNoiseRos2 Ros2Covariance(const FitNoiseOptions& o, const FitNoiseResult& f, double wheelbase_m) {
  const Ros2Noise k = Ros2NoiseOf(o, f);
  const OdometryCovariance cov = OdometryCovarianceFromWheelNoise(k.k_L, k.k_R, wheelbase_m, o.covariance);
  std::vector<std::string> comment{
      fmt::format("ros2_control diff_drive_controller covariance from umbmark fit-noise: k_L = {:.4g}, k_R = {:.4g} "
                  "m^1/2, wheelbase {} m", k.k_L, k.k_R, wheelbase_m)};
  comment.insert(comment.end(), k.comments.begin(), k.comments.end());
  comment.push_back(fmt::format("stated for {} m/s at {} Hz updates (variances scale with speed; derivation: docs/ros2.md)",
                                o.covariance.speed_mps, o.covariance.rate_hz));
  comment.push_back(fmt::format("{} = not measured by planar odometry (z, roll, pitch and rates); {} = lateral velocity "
                                "(non-holonomic constraint)", kUnmeasuredVariance, kConstraintVariance));
  FitNoiseRos2 r;
  r.file = o.ros2_file;
  r.controller = o.controller;
  r.rate_hz = o.covariance.rate_hz;
  r.speed_mps = o.covariance.speed_mps;
  r.k_L = k.k_L;
  r.k_R = k.k_R;
  r.k_L_source = k.kL_source;
  r.k_R_source = k.kR_source;
  r.pose_covariance_diagonal = cov.pose;
  r.twist_covariance_diagonal = cov.twist;
  r.yaml = io::FormatDiffDriveCovariance(o.controller, cov.pose, cov.twist, comment);
  return r;
}

nlohmann::json JsonMatrix(const PoseCovariance& P) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) rows.push_back({P(i, 0), P(i, 1), P(i, 2)});
  return rows;
}

}  // namespace

std::string FitNoiseOptions::Check() const {
  if (inputs.empty()) return "inputs: give at least one endpoint or trajectory CSV or campaign manifest (DATA)";
  if (std::string err = robot.Check(); !err.empty()) return err;
  if (distance_m && !(std::isfinite(*distance_m) && *distance_m > 0.0))
    return fmt::format("distance_m = {}: --distance must be a finite number > 0", *distance_m);
  if (meas_sigma.size() > 2) return "--meas-sigma takes SXY or SXY,STHETA";
  for (const double v : meas_sigma)
    if (!(v >= 0.0)) return "--meas-sigma values must be >= 0";
  if (systematic != "estimate" && systematic != "none")
    return fmt::format("systematic = '{}': --systematic must be estimate or none", systematic);
  if (!ros2_file.empty())
    if (std::string err = covariance.Validate(); !err.empty()) return err;
  return {};
}

// Read, fit, the warnings and notes, then --ros2's covariance (which may
// refuse, QualityGateError, before the caller writes anything).
FitNoiseResult FitNoise(const FitNoiseOptions& o) {
  if (const std::string err = o.Check(); !err.empty()) throw InvalidOptions(err);
  Loaded data = Load(o);
  if (data.runs.empty()) throw InputError(o.inputs.front(), "no run with ground truth at its start and end");
  if (!o.ros2_file.empty() && !data.wheelbase_m)
    throw InvalidOptions("--ros2 needs the robot's wheelbase (--robot or --wheelbase)");
  FitNoiseResult f = Fit(o, data);
  f.skipped_runs = data.skipped;
  f.meas_sigma = {data.sigma_xy, data.sigma_theta};
  f.second_order = !o.first_order;
  f.restricted = !o.ml;
  f.inputs = data.sources;
  f.warnings = Warnings(data, f);
  f.notes = Notes(f);
  for (std::string& w : Ros2Warnings(o, f)) f.warnings.push_back(std::move(w));
  if (!o.ros2_file.empty()) f.ros2 = Ros2Covariance(o, f, *data.wheelbase_m);
  return f;
}

/// The JSON document (contract keys first).
nlohmann::json ToJson(const FitNoiseResult& f) {
  const WheelNoiseFitSummary& s = f.fit;
  nlohmann::json gof = nlohmann::json::array();
  for (const auto& g : s.goodness_of_fit)
    gof.push_back({{"element", g.element},
                   {"observed", g.observed},
                   {"predicted", g.predicted},
                   {"standard_error", g.standard_error},
                   {"z", g.z},
                   {"runs", g.runs}});
  std::map<std::string, int> per_group;
  for (const int g : s.group_of_run) ++per_group[s.groups[static_cast<std::size_t>(g)]];
  nlohmann::json groups = nlohmann::json::array();
  for (std::size_t g = 0; g < s.groups.size(); ++g) {
    groups.push_back({{"group", s.groups[g]},
                      {"runs", per_group[s.groups[g]]},
                      {"systematic_mean", {s.group_means[g](0), s.group_means[g](1), s.group_means[g](2)}}});
  }
  nlohmann::json j = {{"k_L", s.k_L},
                      {"k_R", s.k_R},
                      {"k_L_ci95", {JsonNumber(s.k_L_ci[0]), JsonNumber(s.k_L_ci[1])}},
                      {"k_R_ci95", {JsonNumber(s.k_R_ci[0]), JsonNumber(s.k_R_ci[1])}},
                      {"runs", s.runs},
                      {"skipped_runs", f.skipped_runs},
                      {"groups", groups},
                      {"meas_sigma", f.meas_sigma},
                      {"second_order", f.second_order},
                      {"restricted", f.restricted},
                      {"neg_log_likelihood", s.neg_log_likelihood},
                      {"goodness_of_fit", gof},
                      {"observed_covariance", JsonMatrix(s.observed_covariance)},
                      {"predicted_covariance", JsonMatrix(s.predicted_covariance)},
                      {"inputs", f.inputs}};
  j["k_L_determined"] = f.k_L_determined;
  j["k_R_determined"] = f.k_R_determined;
  j["k_L_upper95"] = JsonNumber(s.k_L_ci[1]);
  j["k_R_upper95"] = JsonNumber(s.k_R_ci[1]);
  const SystematicErrors& used = f.systematic_errors.used;
  j["systematic_errors"] = {{"source", f.systematic_errors.source},
                            {"E_b", used.E_b},
                            {"c_L", used.c_L},
                            {"c_R", used.c_R},
                            {"E_d", used.c_R / used.c_L}};
  if (f.systematic_errors.estimate) {
    j["systematic_errors"]["E_d_se"] = f.systematic_errors.estimate->E_d_se;
    j["systematic_errors"]["E_b_se"] = f.systematic_errors.estimate->E_b_se;
    j["systematic_errors"]["E_b_determined"] = f.systematic_errors.estimate->E_b_determined;
    j["systematic_errors"]["E_d_determined"] = f.systematic_errors.estimate->E_d_determined;
  }
  j["likelihood_passes"] = s.likelihood_passes;
  j["warnings"] = f.warnings;
  j["notes"] = f.notes;
  if (f.ros2) {
    const FitNoiseRos2& r = *f.ros2;
    j["ros2"] = {{"file", r.file},
                 {"controller", r.controller},
                 {"rate_hz", r.rate_hz},
                 {"speed_mps", r.speed_mps},
                 {"k_L", r.k_L},
                 {"k_R", r.k_R},
                 {"k_L_source", r.k_L_source},
                 {"k_R_source", r.k_R_source},
                 {"pose_covariance_diagonal", r.pose_covariance_diagonal},
                 {"twist_covariance_diagonal", r.twist_covariance_diagonal}};
  }
  return j;
}


}  // namespace umbmark::api
