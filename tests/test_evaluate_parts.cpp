// `evaluate` reads a large trajectory CSV in two parts on two threads
// (io::FindRunBoundary, TrajectoryReader over a byte range): the parts give
// exactly the runs (and line numbers) of one sequential read; the whole
// command gives the same JSON as the sequential path (taken with --plot);
// a run split across the two parts is still refused with the sequential
// read's message; a quote near the middle means no cut. EvaluateRun's single
// pass equals the TrackRun computation bit for bit.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/angles.hpp"
#include "evaluation/run_track.hpp"
#include "evaluation/trajectory_eval.hpp"
#include "formats/trajectory_csv.hpp"
#include "support/run_cli.hpp"

namespace fs = std::filesystem;
using umbmark::testing::Q;
using umbmark::testing::RunCli;
using umbmark::testing::Slurp;

namespace {

/// `runs` straight runs of `rows` samples (ticks, ground truth on 4 of 5
/// samples, a comment line now and then), run ids r1, r2, ...
std::string Log(int runs, int rows) {
  std::string out = "# a recorder's log\nrun,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad\n";
  auto buf = fmt::memory_buffer();
  for (int r = 1; r <= runs; ++r) {
    for (int i = 0; i < rows; ++i) {
      const double x = 0.0004 * i * (1.0 + 0.001 * r);
      fmt::format_to(std::back_inserter(buf), "r{},{},{:.3f},{},{},", r, r % 2 ? "cw" : "ccw", 0.01 * i, 7 * i,
                     7 * i + (i * r) / 50);
      if (i % 5 == 3 && i + 1 < rows)
        fmt::format_to(std::back_inserter(buf), ",,\n");
      else
        fmt::format_to(std::back_inserter(buf), "{:.6f},{:.6f},{:.6f}\n", x, 1e-5 * i * r, 1e-6 * i);
      if (i == rows / 2 && r % 7 == 0) fmt::format_to(std::back_inserter(buf), "# marker\n");
    }
  }
  out.append(buf.data(), buf.size());
  return out;
}

void Put(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

}  // namespace

TEST_CASE("two parts cut at a run boundary read exactly like the whole file", "[io][parts]") {
  const fs::path dir = umbmark::testing::TempDir("parts");
  const fs::path file = dir / "log.csv";
  const std::string text = Log(40, 500);
  Put(file, text);
  umbmark::io::TrajectoryReader whole(file.string());
  const auto cut = umbmark::io::FindRunBoundary(file.string(), text.size() / 2, whole.run_column());
  REQUIRE(cut.has_value());
  // The cut is the start of a row whose run differs from the row before.
  REQUIRE(text[*cut - 1] == '\n');
  const std::string next = text.substr(*cut, text.find(',', *cut) - *cut);
  std::size_t prev_start = text.rfind('\n', *cut - 2) + 1;
  while (text[prev_start] == '#') prev_start = text.rfind('\n', prev_start - 2) + 1;
  CHECK(next != text.substr(prev_start, text.find(',', prev_start) - prev_start));
  CHECK(*cut >= text.size() / 2);
  // Line numbers: 1 + line breaks before the offset.
  const auto line = umbmark::io::LineAtOffset(file.string(), *cut);
  CHECK(line == 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + static_cast<long>(*cut), '\n')));

  umbmark::io::TrajectoryReader first(whole, whole.offset(), *cut, whole.next_line());
  umbmark::io::TrajectoryReader second(whole, *cut, text.size(), line);
  umbmark::io::TrajectoryReader sequential(file.string());
  umbmark::TrajectoryRun a, b;
  int runs = 0;
  while (sequential.NextRun(a)) {
    if (!first.NextRun(b)) REQUIRE(second.NextRun(b));
    ++runs;
    INFO("run " << a.run);
    CHECK(b.run == a.run);
    CHECK(b.direction == a.direction);
    CHECK(b.lines == a.lines);
    CHECK(b.t_s == a.t_s);
    CHECK(b.ticks_right == a.ticks_right);
    CHECK(b.gt_y_m.size() == a.gt_y_m.size());
  }
  CHECK(runs == 40);
  CHECK_FALSE(first.NextRun(b));
  CHECK_FALSE(second.NextRun(b));

  // A quote in the window: no cut.
  std::string quoted = text;
  quoted.replace(quoted.find("\nr25,") + 1, 3, "\"r25\"");
  Put(dir / "quoted.csv", quoted);
  CHECK_FALSE(umbmark::io::FindRunBoundary((dir / "quoted.csv").string(), quoted.size() / 2, 0).has_value());
}

TEST_CASE("evaluate on a large file: the parallel parts give the sequential result", "[cli][parts]") {
  const fs::path dir = umbmark::testing::TempDir("parts-cli");
  Put(dir / "robot.toml", "wheelbase_m = 0.34\nwheel_diameter_left_m = 0.1524\nwheel_diameter_right_m = 0.1524\n"
                          "ticks_per_rev = 2048\n");
  const std::string text = Log(140, 5000);  // about 34 MB: above the 32 MB from which evaluate cuts
  REQUIRE(text.size() > (std::size_t{32} << 20));
  Put(dir / "log.csv", text);
  const std::string base = "evaluate " + Q(dir / "log.csv") + " --robot " + Q(dir / "robot.toml");
  const auto parts = RunCli(base + " --json -");
  const auto sequential = RunCli(base + " --json - --plot " + Q(dir / "p.svg"));  // --plot: one pass
  INFO(parts.err << sequential.err);
  REQUIRE(parts.status == 0);
  REQUIRE(sequential.status == 0);
  auto a = nlohmann::json::parse(parts.out), b = nlohmann::json::parse(sequential.out);
  CHECK(a["runs"].size() == 140);
  CHECK(a["runs"] == b["runs"]);
  CHECK(a["summary"] == b["summary"]);
  CHECK(a["warnings"] == b["warnings"]);

  // Run r3 comes back at the very end (in the second part): the sequential message, naming the line.
  std::string split = text;
  const std::size_t r3 = split.find("\nr3,") + 1;
  split += split.substr(r3, split.find('\n', r3) + 1 - r3);
  Put(dir / "log.csv", split);
  const auto bad = RunCli(base);
  const auto bad_sequential = RunCli(base + " --plot " + Q(dir / "p.svg"));
  CHECK(bad.status == 1);
  CHECK_THAT(bad.err, Catch::Contains("run 'r3' appears again after run 'r140'"));
  CHECK(bad.err == bad_sequential.err);
}

// EvaluateRun's one pass against the per-sample track (TrackRun) it replaces
// in the hot path: bit for bit the same numbers, for ticks and wheel travel,
// both integrators, samples without ground truth, heading wrapped to
// (-pi, pi] in the file, and a start pose far from the origin.
TEST_CASE("EvaluateRun equals the TrackRun computation bit for bit", "[evaluation][parts]") {
  using namespace umbmark;
  RobotParams recorded;
  recorded.wheelbase_m = 0.34;
  recorded.wheel_diameter_left_m = 0.1524;
  recorded.wheel_diameter_right_m = 0.1524;
  recorded.ticks_per_rev = 2048;
  RobotParams params = recorded;
  params.wheelbase_m = 0.3412;
  params.wheel_diameter_left_m = 0.1519;
  for (const bool ticks : {true, false}) {
    for (const Integrator integ : {Integrator::kArc, Integrator::kMidpoint}) {
      TrajectoryRun run;
      run.run = "7";
      run.direction = "ccw";
      double x = 3.0, y = -2.0, theta = 2.9;
      for (int i = 0; i < 900; ++i) {
        const double dl = 0.004 + 0.002 * std::sin(0.01 * i), dr = 0.004 + 0.002 * std::cos(0.013 * i);
        theta += (dr - dl) / 0.34;
        x += 0.5 * (dl + dr) * std::cos(theta);
        y += 0.5 * (dl + dr) * std::sin(theta);
        run.t_s.push_back(0.01 * i);
        if (ticks) {
          run.ticks_left.push_back(1000 + static_cast<std::int64_t>(i * 3.1));
          run.ticks_right.push_back(-50 + static_cast<std::int64_t>(i * 3.3));
        } else {
          run.dist_left_m.push_back(0.004 * i);
          run.dist_right_m.push_back(0.0043 * i);
        }
        const bool gt = i % 5 != 3 || i == 899;
        const double nan = std::numeric_limits<double>::quiet_NaN();
        run.gt_x_m.push_back(gt ? x : nan);
        run.gt_y_m.push_back(gt ? y : nan);
        run.gt_theta_rad.push_back(gt ? WrapAngle(theta) : nan);
        run.lines.push_back(static_cast<std::size_t>(i + 2));
      }
      INFO("ticks " << ticks << ", integrator " << IntegratorToString(integ));
      const RunEvaluation ev = EvaluateRun(run, "f.csv", "e", params, recorded, integ);
      const RunTrack t = TrackRun(run, "f.csv", params, recorded, integ);
      double max_pos = 0.0, max_head = 0.0;
      for (std::size_t i = 0; i < run.size(); ++i) {
        if (!t.has_ground_truth[i]) continue;
        max_pos = std::max(max_pos, std::hypot(t.ground_truth[i].x - t.odometry[i].x, t.ground_truth[i].y - t.odometry[i].y));
        max_head = std::max(max_head, std::abs(WrapAngle(t.ground_truth[i].theta - t.odometry[i].theta)));
      }
      const Pose2 g = t.ground_truth[t.last_gt], o = t.odometry[t.last_gt];
      CHECK(ev.max_position_error_m == max_pos);
      CHECK(ev.max_heading_error_rad == max_head);
      CHECK(ev.final_position_error_m == std::hypot(g.x - o.x, g.y - o.y));
      CHECK(ev.final_heading_error_rad == std::abs(WrapAngle(g.theta - o.theta)));
      CHECK(ev.return_error.x == g.x - o.x);
      CHECK(ev.return_error.y == g.y - o.y);
      CHECK(ev.return_error.theta == WrapAngle(g.theta - o.theta));
      CHECK(ev.max_position_error_m > 1e-3);  // the parameters differ: a real error, not 0 == 0
    }
  }
}
