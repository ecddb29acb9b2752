// Refined calibration (calibrate --refine), end to end on its library API:
// recovery of known parameters from noise-free synthetic squares (return
// errors and trajectories, large systematic errors, 1e-6 relative), the
// composition of sets recorded with different parameters, the
// identifiability gate (scale freed on squares), the solver gate, option and
// input checks, the JSON object, the coverage of the 95 % intervals over
// hundreds of seeds, and the real OptiOdom June squares against the
// published OptiOdom calibration.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "calibration/refine.hpp"
#include "calibration/umbmark.hpp"
#include "evaluation/trajectory_eval.hpp"
#include "import/optiodom.hpp"
#include "test_refine_support.hpp"

using namespace umbmark;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

const RobotParams kRecorded{0.34, 0.1524, 0.1524, std::nullopt};

SquareRunSet NoiseFreeSet(double side, const RobotParams& recorded, const test::TrueRobot& truth, int runs) {
  std::mt19937_64 rng(1);
  SquareRunSet set;
  set.side_m = side;
  set.recorded = recorded;
  set.source = "side " + std::to_string(side);
  set.errors = test::SimulateReturnErrors(side, recorded.wheelbase_m, truth, runs, {}, rng);
  return set;
}

bool Covers(const RefineInterval& iv, double v) { return iv.low <= v && v <= iv.high; }

}  // namespace

TEST_CASE("refine from return errors: noise-free large errors are recovered exactly", "[refine][recovery]") {
  const double E_b = 0.90, E_d = 1.02;
  const test::TrueRobot truth = test::FromFactors(E_b, E_d);
  std::vector<SquareRunSet> sets;
  for (double side : {1.0, 2.0, 3.0, 4.0}) sets.push_back(NoiseFreeSet(side, kRecorded, truth, 3));

  // The classic solution (linearised, centres of gravity) as the start, and
  // its bias at this size.
  UmbmarkOptions uo;
  uo.side_m = 4.0;
  const UmbmarkSummary classic = CalibrateUmbmark(sets.back().errors, kRecorded, uo);
  std::printf("classic UMBmark at E_b = %.2f, E_d = %.2f, 4 m: E_b = %.6f (bias %+.2e), E_d = %.6f (bias %+.2e)\n",
              E_b, E_d, classic.selected.E_b, classic.selected.E_b - E_b, classic.selected.E_d,
              classic.selected.E_d - E_d);
  CHECK(std::abs(classic.selected.E_b - E_b) > 1e-4);  // the linearisation visibly misses at this size

  RefineOptions o;
  o.start.E_b = classic.selected.E_b;
  o.start.E_d = classic.selected.E_d;
  const RefineSummary r = RefineFromReturnErrors(sets, kRecorded, o);
  INFO(RefineReport(r));
  CHECK(r.solver.usable);
  CHECK(r.solver.termination_type == "CONVERGENCE");
  CHECK_FALSE(r.scale_free);
  CHECK_THAT(r.E_b, WithinRel(E_b, 1e-6));
  CHECK_THAT(r.E_d, WithinRel(E_d, 1e-6));
  CHECK(r.E_s == 1.0);
  CHECK_THAT(r.refined.wheelbase_m, WithinRel(E_b * kRecorded.wheelbase_m, 1e-6));
  CHECK_THAT(r.refined.wheel_diameter_left_m, WithinRel(truth.c_L * kRecorded.wheel_diameter_left_m, 1e-6));
  CHECK_THAT(r.refined.wheel_diameter_right_m, WithinRel(truth.c_R * kRecorded.wheel_diameter_right_m, 1e-6));
  CHECK_THAT(r.c_R / r.c_L, WithinRel(r.E_d, 1e-12));
  CHECK(r.runs == 24);
  CHECK(r.identifiability.determined == std::vector<std::string>{"E_b", "E_d"});
  CHECK(r.identifiability.fixed_parameters == std::vector<std::string>{"E_s"});
  CHECK(Covers(r.intervals.E_b, E_b));
  CHECK(Covers(r.intervals.E_d, E_d));
  std::printf("refined: E_b = %.9f, E_d = %.9f\n", r.E_b, r.E_d);

  // The same from the reference robot itself as start: the exact model has
  // no other minimum nearby.
  const RefineSummary r0 = RefineFromReturnErrors(sets, kRecorded, RefineOptions{});
  CHECK_THAT(r0.E_b, WithinRel(E_b, 1e-6));
  CHECK_THAT(r0.E_d, WithinRel(E_d, 1e-6));
}

TEST_CASE("refine session_frame: a motion-capture frame error shared by two sessions is recovered exactly",
          "[refine][recovery][session]") {
  // Two sessions of noise-free squares, each seen through its own rigid-body
  // frame error T = (origin o, yaw a) against the axle midpoint: the ground
  // truth of a run, in its first pose's frame, is T^-1 P T (position
  // R(-a) (p + (R(theta) - I) o), heading unchanged), written here
  // independently of the library's correction. session_frame must recover
  // the robot to 1e-6; the first-sample frame (no frame model) is biased.
  const double E_b = 0.97, E_d = 1.01, E_s = 1.005;
  const test::TrueRobot truth = test::FromFactors(E_b, E_d, E_s);
  std::mt19937_64 rng(5);
  const double frames[2][3] = {{0.02, 0.03, -0.02}, {-0.015, -0.01, 0.025}};  // a [rad], o_x, o_y [m]
  std::vector<TrajectoryData> sessions(2);
  for (int s = 0; s < 2; ++s) {
    sessions[s].path = "session " + std::to_string(s);
    const double a = frames[s][0], ox = frames[s][1], oy = frames[s][2];
    for (double side : {1.0, 2.0}) {
      for (SquareDirection dir : {SquareDirection::kCw, SquareDirection::kCcw}) {
        TrajectoryRun run = test::SimulateSquareTrajectory(dir, side, kRecorded.wheelbase_m, truth, 0.01, {}, rng,
                                                           std::to_string(sessions[s].runs.size() + 1));
        for (std::size_t i = 0; i < run.size(); ++i) {
          const double th = run.gt_theta_rad[i];
          const double px = run.gt_x_m[i] + (std::cos(th) - 1.0) * ox - std::sin(th) * oy;
          const double py = run.gt_y_m[i] + std::sin(th) * ox + (std::cos(th) - 1.0) * oy;
          run.gt_x_m[i] = std::cos(a) * px + std::sin(a) * py;
          run.gt_y_m[i] = -std::sin(a) * px + std::cos(a) * py;
        }
        sessions[s].runs.push_back(std::move(run));
      }
    }
  }
  const std::vector<TrajectoryRunSet> sets = {{kRecorded, &sessions[0]}, {kRecorded, &sessions[1]}};
  RefineOptions o;
  o.start_pose = StartPose::kSessionFrame;
  const RefineSummary r = RefineFromTrajectories(sets, kRecorded, o);
  INFO(RefineReport(r));
  CHECK_THAT(r.E_b, WithinRel(E_b, 1e-6));
  CHECK_THAT(r.E_d, WithinRel(E_d, 1e-6));
  CHECK_THAT(r.E_s, WithinRel(E_s, 1e-6));
  CHECK(r.trajectory_settings.start_pose == "session_frame");
  bool noted = false;
  for (const auto& n : r.notes) noted = noted || n.find("yaw +20.00 mrad, origin (+30.0, -20.0) mm") != std::string::npos;
  CHECK(noted);
  // Without the frame model the same data cannot be fitted: a biased
  // estimate or a failed gate.
  o.start_pose = StartPose::kFirstSample;
  bool wrong = false;
  try {
    wrong = std::abs(RefineFromTrajectories(sets, kRecorded, o).E_b - E_b) > 1e-3;
  } catch (const RefineError&) {
    wrong = true;
  }
  CHECK(wrong);
}

TEST_CASE("refine from trajectories: noise-free large errors, scale included, recovered exactly",
          "[refine][recovery]") {
  const double E_b = 0.90, E_d = 1.02, E_s = 1.01;
  const test::TrueRobot truth = test::FromFactors(E_b, E_d, E_s);
  std::mt19937_64 rng(3);
  TrajectoryData data;
  data.path = "synthetic";
  for (double side : {1.0, 2.0, 3.0, 4.0}) {
    for (SquareDirection dir : {SquareDirection::kCw, SquareDirection::kCcw}) {
      data.runs.push_back(test::SimulateSquareTrajectory(dir, side, kRecorded.wheelbase_m, truth, 0.01, {}, rng,
                                                         std::to_string(data.runs.size() + 1)));
    }
  }
  const RefineSummary r = RefineFromTrajectories({{kRecorded, &data}}, kRecorded, RefineOptions{});
  INFO(RefineReport(r));
  CHECK(r.scale_free);  // auto: ground truth measures distance
  CHECK_THAT(r.E_b, WithinRel(E_b, 1e-6));
  CHECK_THAT(r.E_d, WithinRel(E_d, 1e-6));
  CHECK_THAT(r.E_s, WithinRel(E_s, 1e-6));
  CHECK_THAT(r.refined.wheelbase_m, WithinRel(E_b * kRecorded.wheelbase_m, 1e-6));
  CHECK_THAT(r.refined.wheel_diameter_left_m, WithinRel(truth.c_L * kRecorded.wheel_diameter_left_m, 1e-6));
  CHECK_THAT(r.refined.wheel_diameter_right_m, WithinRel(truth.c_R * kRecorded.wheel_diameter_right_m, 1e-6));
  CHECK(r.runs == 8);
  CHECK(r.sampled_poses == 8 * 100);
  CHECK(r.covariance_method == "run_clustered");
  CHECK(r.identifiability.determined == std::vector<std::string>{"E_b", "E_d", "E_s"});

  // The scale held fixed at the wrong value (1 instead of 1.01) cannot fit:
  // the estimate moves away from the truth, by far more than 1e-6.
  RefineOptions fixed;
  fixed.scale = ScaleMode::kFixed;
  const RefineSummary rf = RefineFromTrajectories({{kRecorded, &data}}, kRecorded, fixed);
  CHECK_FALSE(rf.scale_free);
  CHECK(rf.E_s == 1.0);
  CHECK(r.final_cost < 1e-16);
  CHECK(rf.final_cost > 1e-4);
}

TEST_CASE("refine: sets recorded with different parameters share one true robot (composition)",
          "[refine][recovery]") {
  // Absolute truth, and two sets: one recorded with the nominal robot, one
  // with an earlier (imperfect) compensation.
  const RobotParams T{0.331, 0.1509, 0.1531, std::nullopt};
  // R2: an earlier pass that got the diameter ratio wrong by E_d = 1.004
  // but kept the mean factor (E_s = 1 relative to R2, as UMBmark does).
  const double E_d2 = 1.004;
  const RobotParams R2{0.336, T.wheel_diameter_left_m * (E_d2 + 1.0) / 2.0,
                       T.wheel_diameter_right_m * (E_d2 + 1.0) / (2.0 * E_d2), std::nullopt};
  auto relative = [&](const RobotParams& rec) {
    return test::TrueRobot{T.wheelbase_m / rec.wheelbase_m, T.wheel_diameter_left_m / rec.wheel_diameter_left_m,
                           T.wheel_diameter_right_m / rec.wheel_diameter_right_m};
  };
  const std::vector<SquareRunSet> sets = {NoiseFreeSet(4.0, kRecorded, relative(kRecorded), 2),
                                          NoiseFreeSet(3.0, R2, relative(R2), 2)};
  // Both sets' mean diameter factor differs from 1, so let the scale free:
  // the large nominal errors make it observable in noise-free data.
  RefineOptions o;
  o.scale = ScaleMode::kFree;
  const RefineSummary both = RefineFromReturnErrors(sets, kRecorded, o);
  INFO(RefineReport(both));
  CHECK_THAT(both.refined.wheelbase_m, WithinRel(T.wheelbase_m, 1e-6));
  CHECK_THAT(both.refined.wheel_diameter_left_m, WithinRel(T.wheel_diameter_left_m, 1e-6));
  CHECK_THAT(both.refined.wheel_diameter_right_m, WithinRel(T.wheel_diameter_right_m, 1e-6));

  // A second pass on the compensated robot alone, relative to it: the scale
  // held (as classic UMBmark does) and E_b, E_d relative to R2 compose with
  // R2 into the truth's wheelbase and diameter ratio.
  const RefineSummary second = RefineFromReturnErrors({sets[1]}, R2, RefineOptions{});
  CHECK_THAT(second.refined.wheelbase_m, WithinRel(T.wheelbase_m, 1e-6));
  CHECK_THAT(second.refined.wheel_diameter_right_m / second.refined.wheel_diameter_left_m,
             WithinRel(T.wheel_diameter_right_m / T.wheel_diameter_left_m, 1e-6));
}

TEST_CASE("refine: the scale freed on squares is reported as not determined", "[refine][identifiability]") {
  SECTION("perfect robot, noise-free: E_s and E_b are exactly collinear") {
    const std::vector<SquareRunSet> sets = {NoiseFreeSet(4.0, kRecorded, test::FromFactors(1.0, 1.0), 3)};
    RefineOptions o;
    o.scale = ScaleMode::kFree;
    try {
      (void)RefineFromReturnErrors(sets, kRecorded, o);
      FAIL("a rank-deficient problem returned numbers");
    } catch (const RefineError& e) {
      const RefineIdentifiability& id = e.summary().identifiability;
      INFO(e.what());
      CHECK(id.rank_deficient);
      CHECK(id.condition_number > o.max_condition_number);
      CHECK(std::find(id.undetermined.begin(), id.undetermined.end(), "E_s") != id.undetermined.end());
      CHECK(std::find(id.undetermined.begin(), id.undetermined.end(), "E_b") != id.undetermined.end());
      CHECK(std::find(id.undetermined.begin(), id.undetermined.end(), "E_d") == id.undetermined.end());
      CHECK_THAT(std::string(e.what()), Contains("rank deficient") && Contains("E_s"));
    }
    // Held fixed (the default), the same data are fine.
    const RefineSummary r = RefineFromReturnErrors(sets, kRecorded, RefineOptions{});
    CHECK_THAT(r.E_b, WithinAbs(1.0, 1e-9));
    CHECK_THAT(r.E_d, WithinAbs(1.0, 1e-9));
  }
  SECTION("realistic errors with wheel noise: E_s far too uncertain") {
    std::mt19937_64 rng(11);
    SquareRunSet set;
    set.side_m = 4.0;
    set.recorded = kRecorded;
    set.errors = test::SimulateReturnErrors(4.0, kRecorded.wheelbase_m, test::FromFactors(0.995, 1.001), 5,
                                            {0.001, 20, 0.002, 0.002}, rng);
    RefineOptions o;
    o.scale = ScaleMode::kFree;
    REQUIRE_THROWS_AS(RefineFromReturnErrors({set}, kRecorded, o), QualityGateError);
    try {
      (void)RefineFromReturnErrors({set}, kRecorded, o);
    } catch (const RefineError& e) {
      const auto& und = e.summary().identifiability.undetermined;
      CHECK(std::find(und.begin(), und.end(), "E_s") != und.end());
    }
    CHECK_NOTHROW(RefineFromReturnErrors({set}, kRecorded, RefineOptions{}));
  }
}

TEST_CASE("refine: a solver that does not converge is a quality-gate failure with the reason", "[refine][gate]") {
  const std::vector<SquareRunSet> sets = {NoiseFreeSet(4.0, kRecorded, test::FromFactors(0.9, 1.02), 2)};
  RefineOptions o;
  o.max_num_iterations = 1;
  try {
    (void)RefineFromReturnErrors(sets, kRecorded, o);
    FAIL("an unconverged solve returned numbers");
  } catch (const RefineError& e) {
    CHECK_FALSE(e.summary().solver.usable);
    CHECK(e.summary().solver.termination_type == "NO_CONVERGENCE");
    CHECK_THAT(std::string(e.what()), Contains("max_num_iterations = 1"));
  }
}

TEST_CASE("refine: options are checked and the bad field is named", "[refine][options]") {
  CHECK(RefineOptions{}.Check().empty());
  auto bad = [](auto mutate, const std::string& field) {
    RefineOptions o;
    mutate(o);
    INFO(field);
    CHECK_THAT(o.Check(), Contains(field));
    CHECK_THROWS_AS(RefineFromReturnErrors({}, kRecorded, o), InvalidOptions);
  };
  bad([](RefineOptions& o) { o.start.E_b = 0.0; }, "start.E_b");
  bad([](RefineOptions& o) { o.start.E_d = -1.0; }, "start.E_d");
  bad([](RefineOptions& o) { o.confidence = 1.0; }, "confidence");
  bad([](RefineOptions& o) { o.max_relative_sigma = std::nan(""); }, "max_relative_sigma");
  bad([](RefineOptions& o) { o.max_condition_number = 0.5; }, "max_condition_number");
  bad([](RefineOptions& o) { o.max_num_iterations = 0; }, "max_num_iterations");
  bad([](RefineOptions& o) { o.function_tolerance = -1.0; }, "function_tolerance");
  bad([](RefineOptions& o) { o.num_threads = 0; }, "num_threads");
  bad([](RefineOptions& o) { o.min_runs_for_group_covariance = 1; }, "min_runs_for_group_covariance");
  bad([](RefineOptions& o) { o.sigma_floor_xy_m = -1e-3; }, "sigma_floor_xy_m");
  bad([](RefineOptions& o) { o.prior_sigma_theta_rad = 0.0; }, "prior_sigma_theta_rad");
  bad([](RefineOptions& o) { o.samples_per_run = 0; }, "samples_per_run");
  bad([](RefineOptions& o) { o.loss_scale_m = 0.0; }, "loss_scale_m");
  bad([](RefineOptions& o) { o.heading_length_m = INFINITY; }, "heading_length_m");
  CHECK(ScaleModeFromString("free") == ScaleMode::kFree);
  CHECK(ScaleModeFromString(ScaleModeToString(ScaleMode::kFixed)) == ScaleMode::kFixed);
  CHECK(TrajectoryCovarianceFromString("solver_scaled") == TrajectoryCovariance::kSolverScaled);
  CHECK_FALSE(ScaleModeFromString("fix").has_value());
  CHECK(RefineInputKindFromString(RefineInputKindToString(RefineInputKind::kTrajectories)) ==
        RefineInputKind::kTrajectories);
}

TEST_CASE("refine: data it cannot use are input errors", "[refine][input]") {
  SquareRunSet set = NoiseFreeSet(2.0, kRecorded, test::FromFactors(0.99, 1.01), 2);
  set.errors[1].direction = "fwd_back";
  set.errors[1].line = 7;
  try {
    (void)RefineFromReturnErrors({set}, kRecorded, RefineOptions{});
    FAIL("unknown direction accepted");
  } catch (const InputError& e) {
    CHECK(e.line() == 7);
    CHECK_THAT(e.message(), Contains("fwd_back"));
  }
  CHECK_THROWS_AS(RefineFromReturnErrors({}, kRecorded, RefineOptions{}), InputError);
  SquareRunSet nan_set = NoiseFreeSet(2.0, kRecorded, test::FromFactors(0.99, 1.01), 2);
  nan_set.errors[0].ex_m = std::nan("");
  CHECK_THROWS_AS(RefineFromReturnErrors({nan_set}, kRecorded, RefineOptions{}), InputError);
  SquareRunSet side_set = NoiseFreeSet(2.0, kRecorded, test::FromFactors(0.99, 1.01), 2);
  side_set.side_m = 0.0;
  CHECK_THROWS_AS(RefineFromReturnErrors({side_set}, kRecorded, RefineOptions{}), InputError);
  TrajectoryData empty;
  empty.path = "empty.csv";
  CHECK_THROWS_AS(RefineFromTrajectories({{kRecorded, &empty}}, kRecorded, RefineOptions{}), InputError);
}

TEST_CASE("refine: the contract's refined JSON object", "[refine][json]") {
  std::mt19937_64 rng(5);
  SquareRunSet set;
  set.side_m = 4.0;
  set.recorded = kRecorded;
  set.errors = test::SimulateReturnErrors(4.0, kRecorded.wheelbase_m, test::FromFactors(0.99, 1.002), 6,
                                          {0.001, 20, 0.002, 0.002}, rng);
  const RefineSummary r = RefineFromReturnErrors({set}, kRecorded, RefineOptions{});
  const nlohmann::json j = RefinedToJson(r);
  REQUIRE(j.contains("parameters"));
  CHECK(j["parameters"]["wheelbase_m"].get<double>() == r.refined.wheelbase_m);
  CHECK(j["parameters"]["wheel_diameter_left_m"].get<double>() == r.refined.wheel_diameter_left_m);
  CHECK(j["parameters"]["wheel_diameter_right_m"].get<double>() == r.refined.wheel_diameter_right_m);
  CHECK(j["final_cost"].get<double>() == r.final_cost);
  CHECK(j["covariance_order"] ==
        nlohmann::json({"wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m"}));
  REQUIRE(j["covariance"].size() == 3);
  for (int a = 0; a < 3; ++a) {
    REQUIRE(j["covariance"][a].size() == 3);
    for (int b = 0; b < 3; ++b) {
      CHECK_THAT(j["covariance"][a][b].get<double>(), WithinAbs(j["covariance"][b][a].get<double>(), 1e-20));
    }
  }
  // The wheelbase interval is the covariance's diagonal times the quantile.
  const double sb = std::sqrt(j["covariance"][0][0].get<double>());
  CHECK_THAT(j["intervals"]["wheelbase_m"]["sigma"].get<double>(), WithinRel(sb, 1e-12));
  CHECK_THAT(j["intervals"]["wheelbase_m"]["high"].get<double>() - r.refined.wheelbase_m,
             WithinRel(r.quantile * sb, 1e-9));
  // 6 runs per direction with heading: each direction's own covariance,
  // t quantile with 5 degrees of freedom.
  CHECK(j["weighting"][0]["method"] == "group_covariance");
  CHECK(j["dof"].get<double>() == 5.0);
  CHECK_THAT(r.quantile, WithinAbs(2.570582, 1e-6));  // t_{0.975}(5)
  for (const char* key : {"E_d", "E_b", "wheel_diameter_left_m", "wheel_diameter_right_m"}) {
    CHECK(j["intervals"].contains(key));
  }
  CHECK_FALSE(j["intervals"].contains("E_s"));  // fixed
  CHECK(j["solver"]["usable"] == true);
  CHECK(j["solver"]["termination_type"] == "CONVERGENCE");
  CHECK(j["identifiability"]["fixed_parameters"] == nlohmann::json({"E_s"}));
  // D_L and D_R move against each other when the scale is held.
  CHECK(r.covariance(1, 2) < 0.0);
}

TEST_CASE("refine from return errors: 95 % intervals cover the truth in 90-98 % of 300 seeds",
          "[refine][coverage]") {
  // UMBmark protocol with realistic errors: 5 runs per direction on 2 m and
  // 4 m squares, wheel noise k = 0.001 m^1/2 (20 pieces per motion) and a
  // measurement noise of 2 mm / 2 mrad on the return error. Tolerance: with
  // 300 seeds the Monte Carlo standard error of a 95 % coverage is 1.3 %;
  // the accepted band 90-98 % is the issue's.
  const test::TrueRobot truth = test::FromFactors(0.99, 1.002);
  const double b = truth.E_b * kRecorded.wheelbase_m, DL = truth.c_L * kRecorded.wheel_diameter_left_m,
               DR = truth.c_R * kRecorded.wheel_diameter_right_m, Ed = truth.c_R / truth.c_L;
  const int seeds = 300;
  int cover[5] = {0, 0, 0, 0, 0};
  for (int s = 0; s < seeds; ++s) {
    std::mt19937_64 rng(1000 + static_cast<std::uint64_t>(s));
    std::vector<SquareRunSet> sets;
    for (double side : {2.0, 4.0}) {
      SquareRunSet set;
      set.side_m = side;
      set.recorded = kRecorded;
      set.errors = test::SimulateReturnErrors(side, kRecorded.wheelbase_m, truth, 5, {0.001, 20, 0.002, 0.002}, rng);
      sets.push_back(std::move(set));
    }
    const RefineSummary r = RefineFromReturnErrors(sets, kRecorded, RefineOptions{});
    cover[0] += Covers(r.intervals.wheelbase_m, b);
    cover[1] += Covers(r.intervals.wheel_diameter_right_m, DR);
    cover[2] += Covers(r.intervals.wheel_diameter_left_m, DL);
    cover[3] += Covers(r.intervals.E_d, Ed);
    cover[4] += Covers(r.intervals.E_b, truth.E_b);
  }
  const char* names[5] = {"wheelbase", "D_R", "D_L", "E_d", "E_b"};
  for (int i = 0; i < 5; ++i) {
    const double c = cover[i] / static_cast<double>(seeds);
    std::printf("return errors: coverage of the 95%% interval of %s over %d seeds: %.3f\n", names[i], seeds, c);
    INFO(names[i] << " coverage " << c);
    CHECK(c >= 0.90);
    CHECK(c <= 0.98);
  }
}

TEST_CASE("refine from trajectories: 95 % intervals cover the truth in 90-98 % of 200 seeds",
          "[refine][coverage]") {
  // 5 cw + 5 ccw 2 m squares per seed with wheel noise k = 0.001 m^1/2 (per
  // 2 cm step), ground truth = true pose; scale free. The run-clustered
  // covariance is what makes these honest (see RefineOptions::covariance);
  // Monte Carlo standard error 1.5 %.
  const test::TrueRobot truth = test::FromFactors(0.99, 1.002, 1.0);
  const double Ed = truth.c_R / truth.c_L;
  const int seeds = 200;
  int cover[6] = {0, 0, 0, 0, 0, 0};
  for (int s = 0; s < seeds; ++s) {
    std::mt19937_64 rng(100 + static_cast<std::uint64_t>(s));
    TrajectoryData data;
    data.path = "synthetic";
    for (int i = 0; i < 5; ++i) {
      for (SquareDirection dir : {SquareDirection::kCw, SquareDirection::kCcw}) {
        data.runs.push_back(test::SimulateSquareTrajectory(dir, 2.0, kRecorded.wheelbase_m, truth, 0.02,
                                                           {0.001, 1, 0.0, 0.0}, rng, std::to_string(i)));
      }
    }
    const RefineSummary r = RefineFromTrajectories({{kRecorded, &data}}, kRecorded, RefineOptions{});
    REQUIRE(r.scale_free);
    cover[0] += Covers(r.intervals.wheelbase_m, truth.E_b * kRecorded.wheelbase_m);
    cover[1] += Covers(r.intervals.wheel_diameter_right_m, truth.c_R * kRecorded.wheel_diameter_right_m);
    cover[2] += Covers(r.intervals.wheel_diameter_left_m, truth.c_L * kRecorded.wheel_diameter_left_m);
    cover[3] += Covers(r.intervals.E_d, Ed);
    cover[4] += Covers(r.intervals.E_b, truth.E_b);
    cover[5] += Covers(r.intervals.E_s, 1.0);
  }
  const char* names[6] = {"wheelbase", "D_R", "D_L", "E_d", "E_b", "E_s"};
  for (int i = 0; i < 6; ++i) {
    const double c = cover[i] / static_cast<double>(seeds);
    std::printf("trajectories: coverage of the 95%% interval of %s over %d seeds: %.3f\n", names[i], seeds, c);
    INFO(names[i] << " coverage " << c);
    CHECK(c >= 0.90);
    CHECK(c <= 0.98);
  }
}

TEST_CASE("refine on the OptiOdom June squares agrees with the published OptiOdom calibration",
          "[refine][optiodom]") {
  // All four square datasets together (28 runs, ~50k samples), trajectories
  // with ground truth. Reference: the OptiOdom method's published per-dataset
  // calibration of the same squares (data/optiodom-2020-06/
  // published-results.csv, rows optiodom,square/...): wheelbase 0.200628 -
  // 0.200658 m, D_R 0.083632 - 0.083723 m, D_L 0.083684 - 0.083794 m. A
  // different full-path method on the same data: agreement to 0.1 % is
  // expected, 10x the spread of the published values.
  const std::string root = std::string(UMBMARK_SOURCE_DIR) + "/data/optiodom-2020-06/square/";
  std::vector<io::OptiOdomDataset> datasets;
  for (const char* id : {"230620202042", "230620202144", "230620202258", "230620202317"}) {
    datasets.push_back(io::ImportOptiOdom(root + id));
  }
  std::vector<TrajectoryRunSet> sets;
  for (const auto& d : datasets) sets.push_back({d.robot, &d.runs});
  const RobotParams reference = datasets.front().robot;
  // The configuration closest to OptiOdom's own (each run's frame at its
  // first ground-truth sample, heading weighted by the wheelbase); the
  // defaults chosen by held-out evidence follow in the next test.
  RefineOptions options;
  options.start_pose = StartPose::kFirstSample;
  options.heading_weight = 1.0;
  const RefineSummary r = RefineFromTrajectories(sets, reference, options);
  std::printf("%s", RefineReport(r).c_str());
  CHECK(r.runs == 28);
  CHECK(r.scale_free);
  CHECK_THAT(r.refined.wheelbase_m, WithinRel((0.200628 + 0.200658) / 2.0, 1e-3));
  CHECK_THAT(r.refined.wheel_diameter_right_m, WithinRel((0.083632 + 0.083723) / 2.0, 1e-3));
  CHECK_THAT(r.refined.wheel_diameter_left_m, WithinRel((0.083684 + 0.083794) / 2.0, 1e-3));
  // The mean diameter is clearly not the recorded 84 mm: the data determine
  // the scale (0.3 % below), with an interval that excludes 1.
  CHECK(r.intervals.E_s.high < 1.0);
  CHECK(r.identifiability.undetermined.empty());
}

TEST_CASE("refine defaults beat plain least squares across recording sessions of the same robot",
          "[refine][optiodom][heldout]") {
  // Cross-session held-out check (docs/calibration-comparison.md): each
  // June square session calibrates the robot, which is then evaluated on
  // the mean final position error of every OTHER session (the other three
  // square sessions of 23 June, the six circular and four ivanjko sessions
  // of 25 June: paths and days the fit never saw). Reference row: plain
  // least squares (PlainLeastSquaresOptions). The defaults must do better
  // for every square session, and by at least 0.1 mm over all 52 pairs
  // (measured: 11.17 vs 11.33 mm with first_sample, heading weight 1, the
  // defaults since issue 30's second round; the first-round session_frame
  // gave 10.89 here and lost on another night: docs/calibration-comparison.md).
  const std::string root = std::string(UMBMARK_SOURCE_DIR) + "/data/optiodom-2020-06/";
  const std::vector<std::string> squares = {"square/230620202042", "square/230620202144", "square/230620202258",
                                            "square/230620202317"};
  std::vector<std::string> ids = squares;
  for (const char* id : {"circular/250620202104", "circular/250620202119", "circular/250620202236",
                         "circular/250620202251", "circular/250620202317", "circular/250620202345",
                         "ivanjko/250620201618", "ivanjko/250620201636", "ivanjko/250620201655",
                         "ivanjko/250620201738"}) {
    ids.push_back(id);
  }
  std::vector<io::OptiOdomDataset> sets;
  for (const auto& id : ids) sets.push_back(io::ImportOptiOdom(root + id));
  auto mean_error = [&](const RobotParams& p, std::size_t source) {
    double sum = 0.0;
    for (std::size_t t = 0; t < sets.size(); ++t) {
      if (t == source) continue;
      sum += Summarise(EvaluateRuns(sets[t].runs, sets[t].id, p, sets[t].robot, Integrator::kArc))
                 .mean_final_position_error_m;
    }
    return sum / static_cast<double>(sets.size() - 1);
  };
  double refined_sum = 0.0, plain_sum = 0.0;
  for (std::size_t s = 0; s < squares.size(); ++s) {
    const io::OptiOdomDataset& sq = sets[s];
    const double refined =
        mean_error(RefineFromTrajectories({{sq.robot, &sq.runs}}, sq.robot, RefineOptions{}).refined, s);
    const double plain =
        mean_error(RefineFromTrajectories({{sq.robot, &sq.runs}}, sq.robot, PlainLeastSquaresOptions()).refined, s);
    INFO(sq.id << ": refined " << refined * 1e3 << " mm, plain least squares " << plain * 1e3 << " mm");
    CHECK(refined < plain);
    refined_sum += refined;
    plain_sum += plain;
  }
  CHECK(refined_sum / 4.0 < plain_sum / 4.0 - 1e-4);
}
