// Bitwise reproducibility of the simulators across refactoring: the campaign
// simulator's written files and the Monte Carlo kernel's poses and traces
// for fixed seeds, hashed (FNV-1a 64 over the CSV text or the raw doubles).
// The expected hashes were recorded from the code before the true-robot
// model moved into lib/model (commit ced96f3, main of 2026-11-24): a change
// that alters any simulated number by one ulp fails here. A deliberate
// change of the simulators' numbers must re-record them and say why.
#include <catch2/catch.hpp>

#include <cstdint>
#include <cmath>
#include <cstring>
#include <string>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "calibration/umbmark.hpp"
#include "formats/campaign_writer.hpp"
#include "model/commanded_square.hpp"
#include "model/true_robot.hpp"
#include "simulation/campaign_sim.hpp"
#include "simulation/monte_carlo_kernel.hpp"
#include "simulation/monte_carlo_plan.hpp"

using namespace umbmark;
using namespace umbmark::sim;

namespace {

struct Fnv1a {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  void Bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) {
      h ^= b[i];
      h *= 0x100000001b3ULL;
    }
  }
  void Text(const std::string& s) { Bytes(s.data(), s.size()); }
  void Number(double v) { Bytes(&v, sizeof v); }
  void Pose(const Pose2& p) {
    Number(p.x);
    Number(p.y);
    Number(p.theta);
  }
  std::string Hex() const { return fmt::format("{:016x}", h); }
};

RobotParams Robot(bool ticks) {
  RobotParams r;
  r.wheelbase_m = 0.3;
  r.wheel_diameter_left_m = 0.08;
  r.wheel_diameter_right_m = 0.081;
  if (ticks) r.ticks_per_rev = 2796.8;
  return r;
}

/// Every effect on, with a square, a back-and-forth and a figure-eight.
CampaignSimOptions AllEffects() {
  CampaignSimOptions o;
  o.seed = 2024;
  o.square_runs_per_direction = 2;
  o.back_and_forth_runs = 2;
  o.free_runs = 1;
  o.truth = {1.004, 0.993, 0.002, 0.003};
  Effects& e = o.effects;
  e.scale_s = 0.01;
  e.scrub_k = 0.03;
  e.asymmetry_a = 0.004;
  e.castor_kappa = 0.002;
  e.bump_rate = 0.4;
  e.bump_sigma = 0.002;
  e.noise_rho = 0.3;
  e.drift_r = 0.001;
  e.gt_dx = 0.01;
  e.gt_dy = -0.005;
  e.time_tau = 0.03;
  e.yaw_delta = 0.002;
  e.slope_g = 0.001;
  e.slope_dir = 0.7;
  return o;
}

Manifest CampaignManifest(bool ticks) {
  Manifest m = StandardCampaignManifest(Robot(ticks), 1.0, 1.5, GroundTruthNoise{3e-4, 2e-3});
  Experiment free;
  free.kind = ExperimentKind::kFree;
  free.file = free.resolved_file = "free.csv";
  m.experiments.push_back(free);
  return m;
}

std::string CampaignHash(const SimulatedCampaign& c) {
  Fnv1a h;
  h.Text(io::FormatManifest(c.manifest));
  for (const ExperimentData& d : c.data) {
    if (const auto* t = std::get_if<TrajectoryData>(&d))
      h.Text(io::FormatTrajectoryCsv(*t));
    else
      h.Text(io::FormatEndpointCsv(std::get<EndpointData>(d)));
  }
  return h.Hex();
}

SimPlan MonteCarloPlan(bool quantised) {
  SimulationModel m;
  m.nominal = Robot(quantised);
  m.truth = {1.003, 0.995, 0.004};
  m.noise = {0.002, 0.0025};
  m.quantise_encoders = quantised;
  m.initial_covariance.diagonal() << 1e-6, 2e-6, 1e-5;
  return CompilePlan(m, {{1.0, 1.0}, {-0.2356, 0.2356}, {2.0, 1.5}, {-1.0, -1.0}}, 40);
}

}  // namespace

TEST_CASE("campaign simulator: files bit for bit as recorded (ticks, all effects)", "[bitwise]") {
  CHECK(CampaignHash(SimulateCampaign(CampaignManifest(true), AllEffects())) == "947689c5af13755b");
}

TEST_CASE("campaign simulator: files bit for bit as recorded (distances, endpoint squares)", "[bitwise]") {
  CampaignSimOptions o = AllEffects();
  o.seed = 7;
  o.endpoint_squares = true;
  CHECK(CampaignHash(SimulateCampaign(CampaignManifest(false), o)) == "84476212c057460b");
}

TEST_CASE("campaign simulator: baseline robot bit for bit as recorded", "[bitwise]") {
  CampaignSimOptions o;
  o.square_runs_per_direction = 2;
  o.back_and_forth_runs = 2;
  o.truth.E_d = 0.997;
  o.truth.E_b = 1.006;
  CHECK(CampaignHash(SimulateCampaign(CampaignManifest(true), o)) == "5fa514ee37a8021f");
}

TEST_CASE("Monte Carlo kernel: final poses and traces bit for bit as recorded", "[bitwise]") {
  for (const bool quantised : {false, true}) {
    INFO("quantised " << quantised);
    const SimPlan plan = MonteCarloPlan(quantised);
    std::vector<Pose2> finals(40);
    SimulateFinalPoses(plan, 99, 5, 40, finals.data());
    Fnv1a h;
    for (const Pose2& p : finals) h.Pose(p);
    h.Pose(plan.odometry_final);
    for (const RunTrace& t : SimulateTraces(plan, 99, 5, 3, 7)) {
      h.Pose(t.start);
      h.Number(t.phase_left);
      h.Number(t.phase_right);
      for (const Pose2& p : t.truth) h.Pose(p);
      for (double w : t.wheel_left_m) h.Number(w);
      for (double w : t.wheel_right_m) h.Number(w);
      for (std::int64_t k : t.ticks_left) h.Bytes(&k, sizeof k);
      for (std::int64_t k : t.ticks_right) h.Bytes(&k, sizeof k);
    }
    CHECK(h.Hex() == (quantised ? "40214adcf7f0364d" : "3bab9cfc2097f86d"));
  }
}

TEST_CASE("calibration's commanded square and corrections bit for bit as recorded", "[bitwise]") {
  Fnv1a h;
  for (const double E_d : {0.99, 1.0, 1.0123}) {
    h.Number(CorrectionLeft(E_d));
    h.Number(CorrectionRight(E_d));
    for (const SquareDirection d : {SquareDirection::kCw, SquareDirection::kCcw})
      h.Pose(SquareReturnError(d, 4.0, 0.34, 1.01, CorrectionLeft(E_d), CorrectionRight(E_d)));
  }
  const RobotParams c = ApplyCorrection(Robot(true), 1.0123, 0.987);
  h.Number(c.wheelbase_m);
  h.Number(c.wheel_diameter_left_m);
  h.Number(c.wheel_diameter_right_m);
  CHECK(h.Hex() == "87ca8c106be72769");
}

TEST_CASE("true-robot model: correction factors, step and stop rule", "[model]") {
  for (const double E_d : {0.98, 1.0, 1.0123}) {
    // c_R / c_L = E_d and (c_L + c_R) / 2 = 1 (B&F eqs. 4.31, 4.32).
    CHECK(CorrectionRight(E_d) / CorrectionLeft(E_d) == Approx(E_d).epsilon(1e-15));
    CHECK(0.5 * (CorrectionLeft(E_d) + CorrectionRight(E_d)) == Approx(1.0).epsilon(1e-15));
  }
  const TrueRobot robot{1.01, 0.99, 0.02};
  CHECK(robot.WheelFactorRight() / robot.WheelFactorLeft() == Approx(1.01).epsilon(1e-15));
  CHECK(robot.Check().empty());
  CHECK(TrueRobot{1.0, 0.0, 0.0}.Check().rfind("E_b", 0) == 0);
  CHECK(TrueRobot{1.0, 1.0, -1.0}.Check().rfind("scale", 0) == 0);
  // Heading factor 1: the kinematic arc step, bit for bit.
  const Pose2 p{0.3, -0.2, 0.7};
  const Pose2 a = TrueStep(p, 0.11, 0.13, 0.34, 1.0), b = DiffDriveStep(p, 0.11, 0.13, 0.34);
  CHECK(a.x == b.x);
  CHECK(a.y == b.y);
  CHECK(a.theta == b.theta);
  // Turn scrub k = 0.1: the heading change is 0.9 (r - l) / b.
  CHECK(TrueStep(Pose2{}, -0.1, 0.1, 0.4, 0.9).theta == Approx(0.9 * 0.5).epsilon(1e-15));
  // Stop rule: forward at T, backward at the top of tick T, else stay.
  CHECK(EncoderStopPosition(318.0, 0.0, 0.4) == 318.0);
  CHECK(EncoderStopPosition(5.0, 318.0, 318.0) == 6.0);
  CHECK(EncoderStopPosition(5.0, 318.0, 318.0, kStopBelowTicks) < 6.0);
  CHECK(std::floor(EncoderStopPosition(5.0, 318.0, 318.0, kStopBelowTicks)) == 5.0);
  CHECK(EncoderStopPosition(7.0, 7.0, 7.25) == 7.25);
}
