// Progress reporting: the library's ProgressCallback (core/progress.hpp)
// is called serialised with a done count that never decreases and ends at
// the total (Monte Carlo, the diagnosis' stages, stage mapping), and the
// app shows a percentage and an ETA only on a terminal (a pseudo-terminal
// from script(1) here), never in a pipe or file, never with --quiet.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <random>
#include <vector>

#include "core/progress.hpp"
#include "error_models/path_covariance.hpp"
#include "error_models/wheel_noise_fit.hpp"
#include "diagnosis/diagnose.hpp"
#include "support/diag_campaign.hpp"
#include "simulation/monte_carlo.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;

namespace {

/// Records every call; flags a concurrent call.
struct Recorder {
  std::vector<std::pair<double, double>> calls;
  std::mutex mutex;
  bool overlapped = false;
  ProgressCallback Callback() {
    return [this](double done, double total) {
      if (!mutex.try_lock()) {
        overlapped = true;
        return;
      }
      calls.emplace_back(done, total);
      mutex.unlock();
    };
  }
  bool Monotone() const {
    for (std::size_t i = 1; i < calls.size(); ++i)
      if (calls[i].first < calls[i - 1].first || calls[i].second != calls[0].second) return false;
    return true;
  }
};

const std::filesystem::path kEx = std::filesystem::path(UMBMARK_SOURCE_DIR) / "data/examples";

}  // namespace

TEST_CASE("progress callback: Monte Carlo reports runs, monotone, reaching the total", "[progress]") {
  sim::SimulationModel model;
  model.nominal.wheelbase_m = 0.3;
  model.nominal.wheel_diameter_left_m = model.nominal.wheel_diameter_right_m = 0.1;
  model.noise.k_L = model.noise.k_R = 1e-3;
  const sim::SimPlan plan = sim::CompilePlan(model, {WheelSegment{2.0, 2.0}}, 10);
  Recorder rec;
  sim::MonteCarloOptions o;
  o.runs = 5000;
  o.threads = 2;
  o.progress = rec.Callback();
  const sim::MonteCarloSummary mc = sim::RunMonteCarlo(plan, o);
  REQUIRE(mc.runs == 5000);
  CHECK_FALSE(rec.overlapped);
  REQUIRE(rec.calls.size() == 79);  // one per block of 64 runs
  CHECK(rec.Monotone());
  CHECK(rec.calls.back() == std::make_pair(5000.0, 5000.0));
  // Without a callback the result is the same (progress never changes numbers).
  o.progress = nullptr;
  const sim::MonteCarloSummary quiet = sim::RunMonteCarlo(plan, o);
  CHECK(quiet.mean.x == mc.mean.x);
  CHECK(quiet.covariance == mc.covariance);
}

TEST_CASE("progress callback: stage mapping and the diagnosis' stages", "[progress]") {
  std::vector<double> seen;
  const ProgressCallback parent = [&](double done, double total) {
    CHECK(total == 1000.0);
    seen.push_back(done);
  };
  const ProgressCallback stage = StageProgress(parent, 400.0, 700.0, 1000.0);
  stage(0.0, 12.0);
  stage(6.0, 12.0);
  stage(12.0, 12.0);
  CHECK(seen == std::vector<double>{400.0, 550.0, 700.0});
  CHECK_FALSE(StageProgress(nullptr, 0.0, 1.0, 1.0));

  // A diagnosis with a significant gap runs every stage.
  testing::SmallCampaign small = testing::MakeSmallCampaign(3, 3, 6);
  small.sim.effects.time_tau = 0.06;
  Recorder rec;
  diag::DiagnoseOptions o;
  o.null_simulations = 40;
  o.pieces.folds = 3;
  o.progress = rec.Callback();
  const diag::DiagnoseSummary d = diag::Diagnose(testing::BuildSmallCampaign(small), o);
  REQUIRE(d.significant);
  CHECK_FALSE(rec.overlapped);
  CHECK(rec.Monotone());
  REQUIRE(rec.calls.size() > 40 + 12);  // every null simulation, every candidate
  CHECK(rec.calls.back() == std::make_pair(1000.0, 1000.0));
  CHECK(rec.calls[39].first == Approx(400.0));  // the null simulations fill 0-400
}

TEST_CASE("umbmark: progress on a terminal only, with percentage; --quiet silences it", "[progress][cli]") {
  using testing::Q;
  // Show the line from the start (the 2 s delay is for people).
  ::setenv("UMBMARK_PROGRESS_DELAY_S", "0", 1);
  const std::string args = "predict --robot " + Q(kEx / "robot.toml") +
                           " --kl 1e-3 --kr 1e-3 --path line:10,turn:3.14,line:10 --monte-carlo 60000 "
                           "--partitions 100 --threads 1";
  // stderr to a file: no progress.
  const auto file = testing::RunCli(args);
  REQUIRE(file.status == 0);
  CHECK(file.err.find('\r') == std::string::npos);
  CHECK(file.err.find("Monte Carlo, 60000 runs:") == std::string::npos);
  if (std::system("command -v script >/dev/null 2>&1") != 0) {
    WARN("script(1) not installed: the terminal half is not checked");
    return;
  }
  const auto dir = testing::TempDir("progress");
  auto on_tty = [&](const std::string& extra) {
    const std::string cmd = "script -qfec \"'" + std::string(UMBMARK_EXE) + "' " + extra + args + "\" /dev/null > " +
                            Q(dir / "tty.txt") + " 2>&1 </dev/null";
    REQUIRE(std::system(cmd.c_str()) == 0);
    return testing::Slurp((dir / "tty.txt").string());
  };
  const std::string shown = on_tty("");
  CHECK(shown.find("\rMonte Carlo, 60000 runs: ") != std::string::npos);
  CHECK(shown.find("% ") != std::string::npos);
  CHECK(shown.find("s left") != std::string::npos);
  CHECK(shown.find("\r\033[K") != std::string::npos);  // the line is cleared at the end
  const std::string quiet = on_tty("--quiet ");
  CHECK(quiet.find("Monte Carlo, 60000 runs: ") == std::string::npos);
  CHECK(quiet.find("Monte Carlo (60000 runs") != std::string::npos);  // the result itself is printed
  ::unsetenv("UMBMARK_PROGRESS_DELAY_S");
}

TEST_CASE("progress callback: fit-noise reports its fit and both intervals", "[progress]") {
  // 40 runs of a 10 m line whose return errors scatter by a few mm.
  const std::vector<WheelSegment> path{{10.0, 10.0}};
  const PathCovarianceSummary pc = PredictPathCovariance(path, 0.3, WheelNoise{}, PoseCovariance::Zero());
  std::mt19937_64 rng(11);
  std::normal_distribution<double> N01;
  std::vector<WheelNoiseFitRun> runs;
  for (int i = 0; i < 40; ++i) {
    WheelNoiseFitRun r;
    r.group = "line";
    r.run = std::to_string(i + 1);
    r.error = Eigen::Vector3d(0.003 * N01(rng), 0.02 * N01(rng), 0.004 * N01(rng));
    r.basis = pc.motion;
    r.measurement = MeasurementCovariance(1e-3, 1e-3, pc.mean);
    runs.push_back(r);
  }
  Recorder rec;
  WheelNoiseFitOptions o;
  o.progress = rec.Callback();
  const WheelNoiseFitSummary s = FitWheelNoise(runs, o);
  CHECK(s.k_L > 0.0);
  REQUIRE(rec.calls.size() == 3);
  CHECK(rec.Monotone());
  CHECK(rec.calls.back() == std::make_pair(3.0, 3.0));
}
