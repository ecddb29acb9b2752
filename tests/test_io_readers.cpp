// Readers of the contract's file formats on well-formed input (tests/data/good
// and inline text): every accepted variant (BOM, CRLF, comments, blank lines,
// any column order, mm/deg units, both-poses endpoint form, empty etheta and
// ground-truth cells, dist_* form) must give exactly the values written.
// Expected values are the decimal literals of the files, converted with the
// same SI formula (x / 1000, x * pi / 180) so equality is exact.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "formats/data_file.hpp"
#include "formats/endpoint_csv.hpp"
#include "formats/manifest.hpp"
#include "formats/robot_toml.hpp"
#include "formats/trajectory_csv.hpp"

using namespace umbmark;

namespace {

std::string Good(const std::string& name) { return std::string(UMBMARK_SOURCE_DIR) + "/tests/data/good/" + name; }

/// Runs `f`, requires an InputError and returns it.
template <typename F>
InputError Thrown(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e;
  }
  FAIL("no InputError thrown");
  return InputError("", "");
}

}  // namespace

TEST_CASE("endpoint CSV with BOM, CRLF, comments, blank lines and shuffled columns", "[io][endpoint]") {
  const EndpointData d = io::ReadEndpointCsv(Good("endpoint_errors.csv"));
  REQUIRE(d.path == Good("endpoint_errors.csv"));
  REQUIRE(d.runs.size() == 4);
  CHECK(d.runs[0].run == "1");
  CHECK(d.runs[0].direction == "cw");
  CHECK(d.runs[0].ex_m == -0.0121);
  CHECK(d.runs[0].ey_m == 0.0344);
  REQUIRE(d.runs[0].etheta_rad.has_value());
  CHECK(*d.runs[0].etheta_rad == 0.0061);
  CHECK(d.runs[0].line == 5);
  // Empty etheta cell -> not measured.
  CHECK(d.runs[1].run == "2");
  CHECK(d.runs[1].ex_m == -0.0150);
  CHECK_FALSE(d.runs[1].etheta_rad.has_value());
  CHECK(d.runs[1].line == 7);
  CHECK(d.runs[2].direction == "ccw");
  CHECK(*d.runs[2].etheta_rad == -0.0045);
  CHECK(d.runs[2].line == 9);
  // Spaces around a cell are trimmed.
  CHECK(d.runs[3].ey_m == -0.0250);
  CHECK(d.runs[3].line == 10);
}

TEST_CASE("endpoint CSV in millimetres and degrees is converted to SI", "[io][endpoint]") {
  const EndpointData d = io::ReadEndpointCsv(Good("endpoint_mm_deg.csv"));
  REQUIRE(d.runs.size() == 2);
  CHECK(d.runs[0].ex_m == -12.1 / 1000.0);
  CHECK(d.runs[0].ey_m == 34.4 / 1000.0);
  CHECK(*d.runs[0].etheta_rad == 0.35 * kPi / 180.0);
  CHECK(d.runs[1].run == "1");
  CHECK(d.runs[1].direction == "ccw");
  CHECK(d.runs[1].ex_m == 8.7 / 1000.0);
  CHECK(*d.runs[1].etheta_rad == -0.26 * kPi / 180.0);
}

TEST_CASE("endpoint CSV both-poses form gives e = absolute - odometry, heading wrapped", "[io][endpoint]") {
  const EndpointData d = io::ReadEndpointCsv(Good("endpoint_poses.csv"));
  REQUIRE(d.runs.size() == 3);
  CHECK(d.runs[0].ex_m == 0.010 - 0.005);
  CHECK(d.runs[0].ey_m == 0.020 - (-0.010));
  // 3.1 - (-3.1) = 6.2 rad wraps to 6.2 - 2 pi = -0.0831853... rad.
  CHECK(*d.runs[0].etheta_rad == Approx(6.2 - 2.0 * kPi).margin(1e-15));
  CHECK(*d.runs[0].etheta_rad < 0.0);
  CHECK(*d.runs[1].etheta_rad == Approx(0.2).margin(1e-15));
  CHECK(d.runs[1].ex_m == -0.002 - 0.001);
  // Both headings empty -> no heading error.
  CHECK(d.runs[2].ex_m == 0.25);
  CHECK(d.runs[2].ey_m == 0.125);
  CHECK_FALSE(d.runs[2].etheta_rad.has_value());
}

TEST_CASE("endpoint CSV without an etheta column", "[io][endpoint]") {
  const EndpointData d = io::ReadEndpointCsv(Good("endpoint_no_etheta.csv"));
  REQUIRE(d.runs.size() == 1);
  CHECK(d.runs[0].run == "A");
  CHECK(d.runs[0].direction == "fwd_back");
  CHECK(d.runs[0].ex_m == 0.001);
  CHECK(d.runs[0].ey_m == -0.002);
  CHECK_FALSE(d.runs[0].etheta_rad.has_value());
}

TEST_CASE("endpoint etheta is wrapped to the interval -pi (excluded) to pi", "[io][endpoint]") {
  const EndpointData d = io::ParseEndpointCsv("run,direction,ex_m,ey_m,etheta_rad\n1,cw,0,0,7\n2,cw,0,0,-3.5\n", "x");
  CHECK(*d.runs[0].etheta_rad == Approx(7.0 - 2.0 * kPi).margin(1e-15));
  CHECK(*d.runs[1].etheta_rad == Approx(-3.5 + 2.0 * kPi).margin(1e-15));
}

TEST_CASE("trajectory CSV with ticks, empty ground-truth cells and int64 extremes", "[io][trajectory]") {
  const TrajectoryData d = io::ReadTrajectoryCsv(Good("trajectory_ticks.csv"));
  REQUIRE(d.runs.size() == 2);
  const TrajectoryRun& a = d.runs[0];
  CHECK(a.run == "1");
  CHECK(a.direction == "cw");
  REQUIRE(a.size() == 3);
  REQUIRE(a.has_ticks());
  CHECK(a.dist_left_m.empty());
  CHECK(a.t_s == std::vector<double>{0.00, 0.05, 0.10});
  CHECK(a.ticks_left == std::vector<std::int64_t>{1000, 1010, 1021});
  CHECK(a.ticks_right == std::vector<std::int64_t>{-5, 6, 17});
  CHECK(a.lines == std::vector<std::size_t>{3, 4, 5});
  CHECK(a.HasGroundTruth(0));
  CHECK_FALSE(a.HasGroundTruth(1));
  CHECK(std::isnan(a.gt_x_m[1]));
  CHECK(std::isnan(a.gt_theta_rad[1]));
  CHECK(a.gt_x_m[2] == 0.0021);
  CHECK(a.gt_y_m[2] == -0.0001);
  CHECK(a.gt_theta_rad[2] == 0.0005);

  const TrajectoryRun& b = d.runs[1];
  CHECK(b.run == "2");
  CHECK(b.direction == "ccw");
  CHECK(b.lines == std::vector<std::size_t>{8, 9, 10});
  CHECK(b.ticks_left[0] == -std::numeric_limits<std::int64_t>::max());
  CHECK(b.ticks_right[0] == std::numeric_limits<std::int64_t>::max());
  CHECK(b.ticks_left[2] == -9223372036854775807 + 17);
  // Unwrapped ground-truth heading is kept as written.
  CHECK(b.gt_theta_rad[2] == 3.3);
}

TEST_CASE("trajectory CSV with dist_* columns, mixed units, any column order", "[io][trajectory]") {
  const TrajectoryData d = io::ReadTrajectoryCsv(Good("trajectory_dist.csv"));
  REQUIRE(d.runs.size() == 1);
  const TrajectoryRun& r = d.runs[0];
  CHECK(r.run == "r1");
  CHECK(r.direction == "free");
  CHECK_FALSE(r.has_ticks());
  CHECK(r.dist_left_m == std::vector<double>{0.0, 0.0101, 0.0203});
  CHECK(r.dist_right_m == std::vector<double>{0.0, 10.5 / 1000.0, 21.0 / 1000.0});
  CHECK(r.t_s == std::vector<double>{0.5, 0.6, 0.7});
  CHECK(r.gt_x_m[2] == 20.25 / 1000.0);
  CHECK(r.gt_y_m[2] == 1.5 / 1000.0);
  CHECK(r.gt_theta_rad[2] == 90.0 * kPi / 180.0);
  CHECK(r.gt_theta_rad[2] == Approx(kPi / 2).margin(1e-15));
  CHECK_FALSE(r.HasGroundTruth(1));
}

TEST_CASE("a single-sample run with ground truth is accepted; last line without newline", "[io][trajectory]") {
  const TrajectoryData d =
      io::ParseTrajectoryCsv("run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad\n7,cw,1,2,3,4,5,6",
                             "mem");
  REQUIRE(d.runs.size() == 1);
  CHECK(d.path == "mem");
  CHECK(d.runs[0].run == "7");
  CHECK(d.runs[0].ticks_right[0] == 3);
  CHECK(d.runs[0].gt_theta_rad[0] == 6.0);
}

TEST_CASE("tick jumps just below 2^30 are accepted, 2^30 is a wrap", "[io][trajectory]") {
  const std::string header = "run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad\n";
  const auto d = io::ParseTrajectoryCsv(header + "1,cw,0,0,0,0,0,0\n1,cw,1,1073741823,-1073741823,0,0,0\n", "ok");
  CHECK(d.runs[0].ticks_left[1] == (std::int64_t{1} << 30) - 1);
  const InputError e = Thrown([&] {
    (void)io::ParseTrajectoryCsv(header + "1,cw,0,0,0,0,0,0\n1,cw,1,5,-1073741824,0,0,0\n", "wrap");
  });
  CHECK(e.line() == 3);
  CHECK(e.column() == 10);
  CHECK(e.message() == "ticks_right jumps by -1073741824 ticks: counter wrap-around?");
  CHECK(std::string(e.what()) == "wrap:3:10: ticks_right jumps by -1073741824 ticks: counter wrap-around?");
}

TEST_CASE("error columns count UTF-8 characters, not bytes", "[io][csv]") {
  // "é" is two bytes each; the bad number is character 11 (byte 13).
  const InputError e =
      Thrown([] { (void)io::ParseEndpointCsv("run,direction,ex_m,ey_m\n1,été,0.1,x\n", "utf8"); });
  CHECK(e.line() == 2);
  CHECK(e.column() == 11);
  CHECK(e.message() == "ey_m: 'x' is not a number");
}

TEST_CASE("ReadRunFile chooses the reader by the header", "[io][data_file]") {
  const io::RunFile endpoint = io::ReadRunFile(Good("endpoint_mm_deg.csv"));
  REQUIRE(std::holds_alternative<EndpointData>(endpoint));
  CHECK(std::get<EndpointData>(endpoint).runs.size() == 2);
  const io::RunFile ticks = io::ReadRunFile(Good("trajectory_ticks.csv"));
  REQUIRE(std::holds_alternative<TrajectoryData>(ticks));
  CHECK(std::get<TrajectoryData>(ticks).runs.size() == 2);
  const io::RunFile dist = io::ReadRunFile(Good("trajectory_dist.csv"));
  REQUIRE(std::holds_alternative<TrajectoryData>(dist));
  CHECK(std::get<TrajectoryData>(dist).runs[0].dist_left_m.size() == 3);
}

TEST_CASE("robot TOML with integer and float values", "[io][robot]") {
  const RobotParams r = io::ReadRobotToml(Good("robot.toml"));
  CHECK(r.wheelbase_m == 0.340);
  CHECK(r.wheel_diameter_left_m == 0.1524);
  CHECK(r.wheel_diameter_right_m == 0.1525);
  REQUIRE(r.ticks_per_rev.has_value());
  CHECK(*r.ticks_per_rev == 2048.0);

  const RobotParams f = io::ReadRobotToml(Good("robot_fractional_ticks.toml"));
  CHECK(f.wheelbase_m == 1.0);
  CHECK(*f.ticks_per_rev == 2796.8);

  const RobotParams n = io::ReadRobotToml(Good("robot_no_ticks.toml"));
  CHECK_FALSE(n.ticks_per_rev.has_value());
  CHECK(n.wheel_diameter_right_m == 0.0842);
}

TEST_CASE("robot TOML faults carry the key's line and column", "[io][robot]") {
  const InputError e = Thrown([] {
    (void)io::ParseRobotToml("wheelbase_m = 0.3\nwheel_diameter_left_m = 0.1\nwheel_diameter_right_m = 0\n", "r.toml");
  });
  CHECK(e.file() == "r.toml");
  CHECK(e.line() == 3);
  CHECK(e.column() == 26);
  CHECK(e.message() == "wheel_diameter_right_m = 0 must be a finite number > 0");
}

TEST_CASE("manifest with every experiment kind and ground-truth noise", "[io][manifest]") {
  const Manifest m = io::ReadManifest(Good("manifest.toml"));
  CHECK(m.path == Good("manifest.toml"));
  CHECK(m.robot.wheelbase_m == 0.2);
  CHECK(*m.robot.ticks_per_rev == 2796.8);
  REQUIRE(m.ground_truth.has_value());
  CHECK(m.ground_truth->sigma_xy_m == 0.0005);
  CHECK(m.ground_truth->sigma_theta_rad == 0.002);
  REQUIRE(m.experiments.size() == 3);
  CHECK(m.experiments[0].kind == ExperimentKind::kSquare);
  CHECK(m.experiments[0].side_m == 4.0);
  CHECK(m.experiments[0].file == "trajectory_ticks.csv");
  CHECK(m.experiments[0].resolved_file == Good("trajectory_ticks.csv"));
  CHECK(m.experiments[1].kind == ExperimentKind::kBackAndForth);
  CHECK(m.experiments[1].distance_m == 10.5);
  CHECK(m.experiments[1].resolved_file == Good("sub/fwd_back.csv"));
  CHECK(m.experiments[2].kind == ExperimentKind::kFree);
  CHECK(m.experiments[2].resolved_file == "/abs/free.csv");
  // The resolved path reaches the experiment file.
  CHECK(io::ReadTrajectoryCsv(m.experiments[0].resolved_file).runs.size() == 2);
}

TEST_CASE("manifest without a directory part and without ground truth", "[io][manifest]") {
  const Manifest m = io::ParseManifest(
      "[robot]\nwheelbase_m = 0.2\nwheel_diameter_left_m = 0.08\nwheel_diameter_right_m = 0.08\n"
      "[[experiment]]\nkind = \"free\"\nfile = \"a.csv\"\n",
      "campaign.toml");
  CHECK_FALSE(m.ground_truth.has_value());
  CHECK(m.experiments[0].resolved_file == "a.csv");
  CHECK_FALSE(m.robot.ticks_per_rev.has_value());
}

TEST_CASE("IsManifestPath", "[io][manifest]") {
  CHECK(io::IsManifestPath("campaign.toml"));
  CHECK(io::IsManifestPath("dir/x.toml"));
  CHECK_FALSE(io::IsManifestPath("runs.csv"));
  CHECK_FALSE(io::IsManifestPath("toml"));
  CHECK_FALSE(io::IsManifestPath("x.toml.csv"));
}

TEST_CASE("column names: unit on a count, unknown suffix on text, case matters", "[io][csv]") {
  const std::string rest = ",ticks_right,x_gt_m,y_gt_m,theta_gt_rad\n1,cw,0,0,0,0,0,0\n";
  const InputError unit = Thrown([&] { (void)io::ParseTrajectoryCsv("run,direction,t_s,ticks_left_deg" + rest, "u"); });
  CHECK(unit.column() == 19);
  CHECK(unit.message() == "column 'ticks_left_deg': ticks_left takes no unit suffix (expected 'ticks_left')");
  const InputError raw = Thrown([&] { (void)io::ParseTrajectoryCsv("run,direction,t_s,ticks_left_raw" + rest, "r"); });
  CHECK(raw.column() == 19);
  CHECK_THAT(raw.message(), Catch::StartsWith("unknown column 'ticks_left_raw' (expected columns: run, direction, t_s,"));
  const InputError caps = Thrown([&] { (void)io::ParseEndpointCsv("Run,direction,ex_m,ey_m\n1,cw,0,0\n", "c"); });
  CHECK(caps.column() == 1);
  CHECK_THAT(caps.message(), Catch::StartsWith("unknown column 'Run'"));
}
