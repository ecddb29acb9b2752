// Faults of single runs (diagnosis/run_faults.hpp, contract `run_faults`):
//  - the robust deviations against a hand computation;
//  - the threshold holds its false-alarm rate: on fresh normal samples
//    (another seed) max |z| exceeds it in alpha of the cases, within the
//    binomial tolerance;
//  - a simulated campaign in which one run's ground-truth clock is shifted
//    by 0.34 s (the January example) names that run, with the
//    offset within 10 %, and fits the effects without it;
//  - a per-run clock of tau_sd = 0.12 s (run_time_offset) is the tail of a
//    per-run effect, not a fault: no run named on four seeds.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "diagnosis/baseline.hpp"
#include "diagnosis/diagnose.hpp"
#include "diagnosis/run_faults.hpp"
#include "simulation/rng.hpp"
#include "support/diag_campaign.hpp"

using namespace umbmark;
using namespace umbmark::diag;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

/// Shifts the ground-truth clock of run `index` of trajectory experiment
/// `e` by tau (contract time_offset): a sample stamped t shows the recorded
/// pose at t - tau, linearly interpolated, held at the run's ends.
void ShiftGroundTruthClock(std::vector<ExperimentData>& data, std::size_t e, std::size_t index, double tau) {
  TrajectoryRun& r = std::get<TrajectoryData>(data[e]).runs[index];
  const TrajectoryRun old = r;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const double q = std::clamp(r.t_s[i] - tau, old.t_s.front(), old.t_s.back());
    const auto it = std::upper_bound(old.t_s.begin(), old.t_s.end(), q);
    const std::size_t k1 = std::min<std::size_t>(static_cast<std::size_t>(it - old.t_s.begin()), old.size() - 1);
    const std::size_t k0 = k1 > 0 ? k1 - 1 : 0;
    const double w = old.t_s[k1] > old.t_s[k0] ? (q - old.t_s[k0]) / (old.t_s[k1] - old.t_s[k0]) : 0.0;
    r.gt_x_m[i] = old.gt_x_m[k0] + w * (old.gt_x_m[k1] - old.gt_x_m[k0]);
    r.gt_y_m[i] = old.gt_y_m[k0] + w * (old.gt_y_m[k1] - old.gt_y_m[k0]);
    r.gt_theta_rad[i] = old.gt_theta_rad[k0] + w * (old.gt_theta_rad[k1] - old.gt_theta_rad[k0]);
  }
}

/// The run-fault test alone under the fitted baseline of a campaign.
RunFaultScan Scan(const CampaignData& c) {
  const MeanModel model(c);
  const BaselineFit base = FitBaseline(c, model, StartBaseline(c, true), BaselineFitOptions{});
  return FindRunFaults(c, model, base, RunFaultOptions{});
}

}  // namespace

TEST_CASE("run faults: robust deviations by hand", "[run-faults]") {
  // x = 1, 2, 3, 4, 100: median 3, |x - 3| = 2, 1, 0, 1, 97 -> MAD 1,
  // s = 1.4826; with se 0 every z is (x - 3) / 1.4826.
  const std::vector<double> z = RobustDeviations({1, 2, 3, 4, 100}, {0, 0, 0, 0, 0});
  REQUIRE(z.size() == 5);
  CHECK_THAT(z[0], WithinAbs(-2.0 / 1.482602218505602, 1e-12));
  CHECK_THAT(z[4], WithinAbs(97.0 / 1.482602218505602, 1e-12));
  // se 1 everywhere: s_b^2 = 1.4826^2 - 1, and the predictive sd is again
  // 1.4826 (homogeneous errors leave z unchanged).
  const std::vector<double> z1 = RobustDeviations({1, 2, 3, 4, 100}, {1, 1, 1, 1, 1});
  CHECK_THAT(z1[4], WithinAbs(z[4], 1e-12));
  // A run measured far worse than the others is judged against its own se:
  // se 10 on the outlier: z = 97 / sqrt(1.4826^2 - 1 + 100).
  const std::vector<double> z2 = RobustDeviations({1, 2, 3, 4, 100}, {1, 1, 1, 1, 10});
  CHECK_THAT(z2[4], WithinAbs(97.0 / std::sqrt(1.482602218505602 * 1.482602218505602 - 1.0 + 100.0), 1e-9));
}

TEST_CASE("run faults: the threshold holds its false-alarm rate", "[run-faults]") {
  for (int n : {6, 25}) {
    const double rate = 0.05;
    const double thr = MaxDeviationThreshold(n, rate, 4000, 11);
    // Fresh samples from another stream: 4000 campaigns, expected 200
    // exceedances, binomial sd 13.8: accept 200 +- 4 sd.
    int over = 0;
    std::vector<double> x(static_cast<std::size_t>(n)), se(static_cast<std::size_t>(n), 0.0);
    for (int s = 0; s < 4000; ++s) {
      sim::Xoshiro256pp g(sim::StreamSeed(987, static_cast<std::uint64_t>(s), 5));
      for (int i = 0; i < n; i += 2) {
        double a = 0.0, b = 0.0;
        const std::uint64_t u = g.Next(), v = g.Next();
        sim::NormalPairFromBits(u, v, a, b);
        x[static_cast<std::size_t>(i)] = a;
        if (i + 1 < n) x[static_cast<std::size_t>(i + 1)] = b;
      }
      double m = 0.0;
      for (double z : RobustDeviations(x, se)) m = std::max(m, std::abs(z));
      over += m > thr;
    }
    INFO("n = " << n << ", threshold " << thr);
    CHECK(over >= 145);
    CHECK(over <= 255);
  }
  // Fewer runs, heavier tails of the robust scale: a higher threshold.
  CHECK(MaxDeviationThreshold(6, 0.01, 4000, 3) > MaxDeviationThreshold(25, 0.01, 4000, 3));
}

TEST_CASE("run faults: one run's clock 0.34 s off is named and left out", "[run-faults][diagnose]") {
  testing::SmallCampaign s = testing::MakeSmallCampaign(91, 5, 10);
  s.sim.sample_rate_hz = 20.0;
  sim::SimulatedCampaign sc = sim::SimulateCampaign(s.manifest, s.sim);
  // Experiment 2 (back and forth), its fourth run.
  REQUIRE(sc.data.size() >= 2);
  ShiftGroundTruthClock(sc.data, 1, 3, 0.34);
  const CampaignData c = BuildCampaign(sc.manifest, sc.data);
  DiagnoseOptions o;
  o.null_simulations = 100;
  const DiagnoseSummary d = Diagnose(c, o);
  REQUIRE(d.run_faults.size() == 1);
  const RunFault& f = d.run_faults.front();
  CHECK(f.experiment == 1);
  CHECK(f.run_id == std::get<TrajectoryData>(sc.data[1]).runs[3].run);
  CHECK(f.statistic == "clock");
  CHECK_THAT(f.tau_s, WithinRel(0.34, 0.10));
  // Fitted without it: one run fewer, and nothing of the clock is left to
  // name.
  CHECK(d.baseline.runs == static_cast<int>(c.runs.size()) - 1);
  INFO(d.verdict_reason);
  CHECK(d.verdict == "none");
}

TEST_CASE("run faults: per-run clocks of tau_sd 0.12 s are no fault", "[run-faults]") {
  for (std::uint64_t seed : {31, 32, 33, 34}) {
    testing::SmallCampaign s = testing::MakeSmallCampaign(seed, 5, 10);
    s.sim.sample_rate_hz = 20.0;
    s.sim.effects.run_tau_sd = 0.12;
    const RunFaultScan scan = Scan(testing::BuildSmallCampaign(s));
    INFO("seed " << seed << ": " << (scan.faults.empty() ? std::string() : scan.faults.front().what));
    CHECK(scan.faults.empty());
    CHECK(scan.threshold_clock > 4.0);
  }
}

TEST_CASE("run faults: the campaign without a run", "[run-faults]") {
  const CampaignData c = testing::BuildSmallCampaign(testing::MakeSmallCampaign(5, 3, 4));
  const CampaignData r = WithoutRuns(c, {1});
  REQUIRE(r.runs.size() == c.runs.size() - 1);
  CHECK(r.runs[1].id == c.runs[2].id);
  CHECK(r.runs[1].campaign_index == c.runs[2].campaign_index);  // parameter_drift keeps its run index
  std::size_t pieces_of_1 = 0;
  for (const Piece& p : c.pieces) pieces_of_1 += p.run == 1;
  CHECK(r.pieces.size() == c.pieces.size() - pieces_of_1);
  for (const Piece& p : r.pieces) CHECK(p.run < static_cast<int>(r.runs.size()));
  const auto& runs0 = std::visit([](const auto& d) { return d.runs.size(); }, c.files[0]);
  const auto& runs1 = std::visit([](const auto& d) { return d.runs.size(); }, r.files[0]);
  CHECK(runs1 == runs0 - 1);
}

TEST_CASE("run faults: one run pushed 8 mm while it stands is named as an event and left out", "[run-faults]") {
  testing::SmallCampaign s = testing::MakeSmallCampaign(57, 5, 10);
  s.sim.sample_rate_hz = 20.0;
  sim::SimulatedCampaign sc = sim::SimulateCampaign(s.manifest, s.sim);
  // Square experiment, third run: from the middle of its third standstill on,
  // the ground truth is 8 mm further along x (a push while the robot stands).
  TrajectoryRun& r = std::get<TrajectoryData>(sc.data[0]).runs[2];
  std::vector<std::size_t> still;
  for (std::size_t i = 1; i < r.size(); ++i)
    if (r.ticks_left[i] == r.ticks_left[i - 1] && r.ticks_right[i] == r.ticks_right[i - 1]) still.push_back(i);
  REQUIRE(still.size() > 40);
  // A sample in the middle of the standstills, away from their ends.
  const std::size_t at = still[still.size() / 2];
  for (std::size_t i = at; i < r.size(); ++i) r.gt_x_m[i] += 0.008;
  const CampaignData c = BuildCampaign(sc.manifest, sc.data);
  const RunFaultScan scan = Scan(c);
  REQUIRE(scan.faults.size() == 1);
  const RunFault& f = scan.faults.front();
  INFO(f.what);
  CHECK(f.experiment == 0);
  CHECK(f.run_id == r.run);
  CHECK(f.statistic == "event");
  CHECK(f.z > scan.threshold_event);
  CHECK(scan.threshold_event > 3.0);
  // The diagnosis names it in plain words first and fits without it.
  DiagnoseOptions o;
  o.null_simulations = 100;
  const DiagnoseSummary d = Diagnose(c, o);
  REQUIRE(d.run_faults.size() == 1);
  CHECK(d.run_faults.front().statistic == "event");
  CHECK_THAT(d.summary, Catch::Matchers::Contains("one moment of it is far off the model"));
  CHECK(d.baseline.runs == static_cast<int>(c.runs.size()) - 1);
}

TEST_CASE("run faults: bumps on every run are no event fault", "[run-faults]") {
  // bump_outliers (rate 0.8 per metre, sigma 6 mm): every run has pieces far
  // off, so no run's largest piece stands out of its experiment's.
  for (std::uint64_t seed : {41, 42, 43}) {
    testing::SmallCampaign s = testing::MakeSmallCampaign(seed, 5, 10);
    s.sim.sample_rate_hz = 20.0;
    s.sim.effects.bump_rate = 0.8;
    s.sim.effects.bump_sigma = 0.006;
    const RunFaultScan scan = Scan(testing::BuildSmallCampaign(s));
    INFO("seed " << seed << ": " << (scan.faults.empty() ? std::string() : scan.faults.front().what));
    CHECK(scan.faults.empty());
  }
}
