// Calibration quality on real data: for each OptiOdom square dataset,
// calibrate with classic UMBmark (x and mean estimators) and with the refined
// fit (endpoint return errors and full trajectories), then evaluate every
// calibration on all circular and ivanjko runs of the same June 2020 folder
// (paths the calibration never saw). The published OptiOdom parameters
// (`optiodom` rows of published-results.csv for the same square datasets)
// are evaluated the same way beside them.
//
// Usage: optiodom_comparison [DATA_DIR]   (default: data/optiodom-2020-06)
// Prints a Markdown table: mean final / mean max / worst final position
// error over the held-out runs, in mm.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "calibration/calibrate_job.hpp"
#include "calibration/refine.hpp"
#include "evaluation/trajectory_eval.hpp"
#include "io/optiodom.hpp"

using namespace umbmark;
namespace fs = std::filesystem;

namespace {

struct HeldOut {
  std::vector<io::OptiOdomDataset> sets;
};

EvaluationSummary EvaluateOn(const HeldOut& h, const RobotParams& params) {
  std::vector<RunEvaluation> all;
  for (const auto& ds : h.sets) {
    auto runs = EvaluateRuns(ds.runs, ds.category + "/" + ds.id, params, ds.robot, Integrator::kArc);
    all.insert(all.end(), runs.begin(), runs.end());
  }
  return Summarise(std::move(all));
}

std::map<std::string, RobotParams> PublishedOptiOdom(const fs::path& csv) {
  std::map<std::string, RobotParams> out;
  std::ifstream f(csv);
  std::string line;
  std::getline(f, line);
  while (std::getline(f, line)) {
    std::erase(line, '\r');
    std::vector<std::string> c;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) c.push_back(cell);
    if (c.size() < 12 || c[0] != "optiodom" || c[1].rfind("square/", 0) != 0) continue;
    RobotParams p;
    p.wheelbase_m = std::stod(c[9]);
    p.wheel_diameter_right_m = std::stod(c[10]);
    p.wheel_diameter_left_m = std::stod(c[11]);
    p.ticks_per_rev = 43.7 * 64;
    out[c[1].substr(7)] = p;
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path root = argc > 1 ? fs::path(argv[1]) : fs::path("data/optiodom-2020-06");
  HeldOut held;
  std::size_t held_runs = 0;
  for (const char* cat : {"circular", "ivanjko"}) {
    std::vector<fs::path> dirs;
    for (const auto& e : fs::directory_iterator(root / cat)) dirs.push_back(e.path());
    std::sort(dirs.begin(), dirs.end());
    for (const auto& d : dirs) {
      held.sets.push_back(io::ImportOptiOdom(d.string()));
      held_runs += held.sets.back().runs.runs.size();
    }
  }
  const auto published = PublishedOptiOdom(root / "published-results.csv");
  std::vector<fs::path> squares;
  for (const auto& e : fs::directory_iterator(root / "square")) squares.push_back(e.path());
  std::sort(squares.begin(), squares.end());

  fmt::print("Held-out evaluation on {} circular + ivanjko runs ({} datasets), odometry with the exact arc.\n\n",
             held_runs, held.sets.size());
  fmt::print("| square dataset | method | wheelbase [m] | D_R [m] | D_L [m] | mean final [mm] | (its SE) | mean max [mm] | worst final [mm] |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|\n");
  auto row = [&](const std::string& ds, const std::string& method, const RobotParams& p) {
    const auto s = EvaluateOn(held, p);
    // Standard error of the mean final error over the held-out runs.
    double ss = 0.0;
    for (const auto& r : s.runs) ss += std::pow(r.final_position_error_m - s.mean_final_position_error_m, 2);
    const double n = static_cast<double>(s.runs.size());
    const double se = std::sqrt(ss / (n - 1.0) / n);
    fmt::print("| {} | {} | {:.6f} | {:.6f} | {:.6f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} |\n", ds, method, p.wheelbase_m,
               p.wheel_diameter_right_m, p.wheel_diameter_left_m, s.mean_final_position_error_m * 1e3, se * 1e3,
               s.mean_max_position_error_m * 1e3, s.max_final_position_error_m * 1e3);
    return s;
  };
  std::map<std::string, std::vector<double>> mean_final;
  for (const auto& sq : squares) {
    const auto ds = io::ImportOptiOdom(sq.string());
    const auto in = InputFromTrajectories(ds.runs, ds.robot, ds.experiment.side_m, Integrator::kArc, ds.id);
    mean_final["recorded (no calibration)"].push_back(row(ds.id, "recorded (no calibration)", ds.robot).mean_final_position_error_m);
    for (auto est : {UmbmarkEstimator::kX, UmbmarkEstimator::kMean}) {
      CalibrateJobOptions o;
      o.umbmark.estimator = est;
      const auto r = RunCalibrateJob(in, o);
      const std::string m = fmt::format("UMBmark ({})", UmbmarkEstimatorToString(est));
      mean_final[m].push_back(row(ds.id, m, r.umbmark.corrected).mean_final_position_error_m);
    }
    {
      CalibrateJobOptions o;
      o.refine = RefineOptions{};
      const auto r = RunCalibrateJob(in, o);
      mean_final["refined (trajectories)"].push_back(
          row(ds.id, "refined (trajectories)", r.refined->refined).mean_final_position_error_m);
    }
    {
      // Refined from the return errors alone (what an endpoint CSV gives).
      CalibrateInput only_errors = in;
      only_errors.trajectories.reset();
      CalibrateJobOptions o;
      o.refine = RefineOptions{};
      try {
        const auto r = RunCalibrateJob(only_errors, o);
        mean_final["refined (return errors)"].push_back(
            row(ds.id, "refined (return errors)", r.refined->refined).mean_final_position_error_m);
      } catch (const QualityGateError& e) {
        fmt::print("| {} | refined (return errors) | quality gate failed: {} |||||\n", ds.id, e.what());
      }
    }
    if (auto it = published.find(ds.id); it != published.end())
      mean_final["published OptiOdom"].push_back(row(ds.id, "published OptiOdom", it->second).mean_final_position_error_m);
  }
  fmt::print("\nAverage of the mean final position error over the four square datasets:\n\n");
  for (const auto& [m, v] : mean_final) {
    double s = 0;
    for (double x : v) s += x;
    fmt::print("- {}: {:.2f} mm\n", m, 1e3 * s / static_cast<double>(v.size()));
  }
  return 0;
}
