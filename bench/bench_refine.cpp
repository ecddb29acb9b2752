// Speed of the refined calibration (calibrate --refine) on real data: all
// four OptiOdom June 2020 square datasets together (28 runs, ~50k encoder
// samples; target: well under a second per refine), from trajectories with
// ground truth and from their return errors.
//   bench_refine [DATA_DIR] [REPEATS]
// DATA_DIR defaults to the repository's data/optiodom-2020-06/square. Each
// refine is timed end to end (preparation, solve, covariance); the median
// over REPEATS (default 10) is reported with throughput figures:
//   problem evaluations/s   Ceres residual + Jacobian evaluations of the
//                           whole problem per second of solver time
//   pose residuals/s        sampled poses evaluated (with Jacobian) per second
//   encoder steps/s         odometry steps integrated (as Jets) per second
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "calibration/refine.hpp"
#include "core/errors.hpp"
#include "evaluation/return_error.hpp"
#include "import/optiodom.hpp"

namespace {

using namespace umbmark;

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

template <typename F>
double TimeIt(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  // Default: the repository's copy, found from this source file's path.
  const std::string dir =
      argc > 1 ? argv[1]
               : (std::filesystem::path(__FILE__).parent_path().parent_path() / "data/optiodom-2020-06/square").string();
  const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 10;
  try {
    std::vector<io::OptiOdomDataset> datasets;
    for (const char* id : {"230620202042", "230620202144", "230620202258", "230620202317"}) {
      datasets.push_back(io::ImportOptiOdom(dir + "/" + id));
    }
    std::vector<TrajectoryRunSet> sets;
    std::size_t runs = 0, samples = 0;
    for (const auto& d : datasets) {
      sets.push_back({d.robot, &d.runs});
      runs += d.runs.runs.size();
      for (const auto& r : d.runs.runs) samples += r.size();
    }
    const RobotParams reference = datasets.front().robot;
    fmt::print("data: {} datasets, {} runs, {} encoder samples\n", datasets.size(), runs, samples);

    // ---- trajectories with ground truth ----
    const RefineOptions options;
    RefineSummary last;
    std::vector<double> times, solver_times;
    for (int i = 0; i < repeats; ++i) {
      times.push_back(TimeIt([&] { last = RefineFromTrajectories(sets, reference, options); }));
      solver_times.push_back(last.solver.solve_time_s);
    }
    const double t = Median(times), ts = Median(solver_times);
    const int evaluations = last.solver.residual_evaluations + last.solver.jacobian_evaluations;
    fmt::print("refine (trajectories): median {:.1f} ms per refine over {} repeats (solver {:.1f} ms), "
               "{} iterations\n",
               1e3 * t, repeats, 1e3 * ts, last.solver.iterations);
    fmt::print("  problem evaluations/s: {:.0f}  ({} residual + {} Jacobian evaluations per solve)\n",
               evaluations / ts, last.solver.residual_evaluations, last.solver.jacobian_evaluations);
    fmt::print("  pose residuals/s:      {:.3g}  ({} sampled poses per evaluation)\n",
               evaluations * static_cast<double>(last.sampled_poses) / ts, last.sampled_poses);
    fmt::print("  encoder steps/s:       {:.3g}\n", evaluations * static_cast<double>(samples) / ts);
    fmt::print("  wheelbase {:.6f} m, D_R {:.6f} m, D_L {:.6f} m\n", last.refined.wheelbase_m,
               last.refined.wheel_diameter_right_m, last.refined.wheel_diameter_left_m);

    // ---- return errors of the same runs ----
    std::vector<SquareRunSet> square_sets;
    for (const auto& d : datasets) {
      square_sets.push_back({d.experiment.side_m, d.robot,
                             ReturnErrorsFromTrajectories(d.runs, d.robot, d.robot, Integrator::kArc), d.id});
    }
    times.clear();
    for (int i = 0; i < repeats; ++i) {
      times.push_back(TimeIt([&] { last = RefineFromReturnErrors(square_sets, reference, options); }));
    }
    fmt::print("refine (return errors): median {:.2f} ms per refine, {} runs, {} iterations, "
               "{:.0f} problem evaluations/s\n",
               1e3 * Median(times), last.runs, last.solver.iterations,
               (last.solver.residual_evaluations + last.solver.jacobian_evaluations) / last.solver.solve_time_s);
  } catch (const std::exception& e) {
    fmt::print(stderr, "bench_refine: {}\n", e.what());
    return 1;
  }
  return 0;
}
