// libFuzzer target for the CSV readers: feeds the same bytes to the endpoint
// and the trajectory parser. Only InputError may escape a reader (anything
// else, a crash or a sanitizer report is a bug); accepted input must satisfy
// the readers' documented guarantees, checked below.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "io/endpoint_csv.hpp"
#include "io/trajectory_csv.hpp"

namespace {

void Require(bool ok) {
  if (!ok) __builtin_trap();
}

void CheckEndpoint(const umbmark::EndpointData& d) {
  Require(!d.runs.empty());
  for (const auto& r : d.runs) {
    Require(!r.run.empty() && !r.direction.empty());
    Require(std::isfinite(r.ex_m) && std::isfinite(r.ey_m));
    if (r.etheta_rad) Require(*r.etheta_rad > -umbmark::kPi && *r.etheta_rad <= umbmark::kPi);
  }
}

void CheckTrajectory(const umbmark::TrajectoryData& d) {
  Require(!d.runs.empty());
  for (const auto& r : d.runs) {
    const std::size_t n = r.size();
    Require(n > 0 && r.lines.size() == n && r.gt_x_m.size() == n && r.gt_y_m.size() == n &&
            r.gt_theta_rad.size() == n);
    Require(r.has_ticks() ? (r.ticks_left.size() == n && r.ticks_right.size() == n && r.dist_left_m.empty())
                          : (r.dist_left_m.size() == n && r.dist_right_m.size() == n));
    Require(r.HasGroundTruth(0) && r.HasGroundTruth(n - 1));
    for (std::size_t i = 1; i < n; ++i) Require(r.t_s[i] > r.t_s[i - 1] && r.lines[i] > r.lines[i - 1]);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    CheckEndpoint(umbmark::io::ParseEndpointCsv(text, "fuzz.csv"));
  } catch (const umbmark::InputError&) {
  }
  try {
    CheckTrajectory(umbmark::io::ParseTrajectoryCsv(text, "fuzz.csv"));
  } catch (const umbmark::InputError&) {
  }
  return 0;
}
