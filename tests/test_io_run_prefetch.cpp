// io::RunPrefetcher (runs read on a second thread for `evaluate`): the same
// runs in the same order as TrajectoryReader::NextRun, a reader fault
// rethrown after the runs before it with the reader's own message, and a
// consumer that stops early neither hangs nor leaks.
#include <catch2/catch.hpp>

#include <string>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "formats/run_prefetch.hpp"
#include "formats/trajectory_csv.hpp"

using namespace umbmark;

namespace {

/// `runs` runs of `rows` samples each (ticks, ground truth at every sample).
std::string Csv(int runs, int rows) {
  std::string out = "run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad\n";
  for (int r = 1; r <= runs; ++r)
    for (int i = 0; i < rows; ++i)
      out += fmt::format("{},cw,{},{},{},{},{},{}\n", r, 0.01 * i, 3 * i + r, 5 * i - r, 0.001 * i, -0.002 * i, 0.0001 * r);
  return out;
}

}  // namespace

TEST_CASE("RunPrefetcher hands out exactly the reader's runs", "[io][prefetch]") {
  const std::string text = Csv(7, 300);
  io::TrajectoryReader direct(text, "a.csv", 4096);
  io::TrajectoryReader ahead(text, "a.csv", 4096);
  io::RunPrefetcher prefetch(ahead);
  TrajectoryRun a, b;
  int n = 0;
  while (direct.NextRun(a)) {
    REQUIRE(prefetch.NextRun(b));
    ++n;
    CHECK(b.run == a.run);
    CHECK(b.direction == a.direction);
    CHECK(b.t_s == a.t_s);
    CHECK(b.ticks_left == a.ticks_left);
    CHECK(b.ticks_right == a.ticks_right);
    CHECK(b.gt_x_m == a.gt_x_m);
    CHECK(b.gt_theta_rad == a.gt_theta_rad);
    CHECK(b.lines == a.lines);
  }
  CHECK(n == 7);
  CHECK_FALSE(prefetch.NextRun(b));
  CHECK_FALSE(prefetch.NextRun(b));  // stays at the end
}

TEST_CASE("RunPrefetcher rethrows a reader fault after the runs before it", "[io][prefetch]") {
  std::string text = Csv(5, 50);
  // Run 4's 10th sample: time goes back (line 1 + 3*50 + 10 = 161).
  const std::string row = fmt::format("\n4,cw,{},", 0.01 * 9);
  const auto at = text.find(row);
  REQUIRE(at != std::string::npos);
  text.replace(at, row.size(), "\n4,cw,0.001,");
  std::string expected;
  try {
    io::TrajectoryReader direct(text, "b.csv");
    TrajectoryRun r;
    while (direct.NextRun(r)) {
    }
  } catch (const InputError& e) {
    expected = e.what();
  }
  REQUIRE_FALSE(expected.empty());
  io::TrajectoryReader ahead(text, "b.csv");
  io::RunPrefetcher prefetch(ahead);
  TrajectoryRun r;
  for (int k = 1; k <= 3; ++k) {
    REQUIRE(prefetch.NextRun(r));
    CHECK(r.run == std::to_string(k));
  }
  try {
    prefetch.NextRun(r);
    FAIL("no exception");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) == expected);
    CHECK_THAT(e.what(), Catch::Contains("b.csv:"));
  }
}

TEST_CASE("RunPrefetcher can be left before the last run", "[io][prefetch]") {
  const std::string text = Csv(20, 200);
  io::TrajectoryReader ahead(text, "c.csv");
  {
    io::RunPrefetcher prefetch(ahead);
    TrajectoryRun r;
    REQUIRE(prefetch.NextRun(r));
    CHECK(r.run == "1");
  }  // joined here, with runs left unread
  TrajectoryRun rest;
  int left = 0;
  while (ahead.NextRun(rest)) ++left;
  CHECK(left >= 17);  // the thread stopped after at most two more runs
  CHECK(left <= 19);
}
