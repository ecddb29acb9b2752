// libFuzzer target for the CSV readers: feeds the same bytes to the endpoint
// and the trajectory parser. Only InputError may escape a reader (anything
// else, a crash or a sanitizer report is a bug); accepted input must satisfy
// the readers' documented guarantees, checked below. The trajectory text is
// also streamed through tiny read() chunks and buffers (sizes taken from the
// input's last bytes), which must give exactly the same runs, or the same
// error message, as one whole read.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "formats/endpoint_csv.hpp"
#include "formats/trajectory_csv.hpp"

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

/// Every value of every run, to compare two readings.
std::string Fingerprint(const umbmark::TrajectoryData& d) {
  std::string out;
  const auto add = [&out](const void* p, std::size_t n) { out.append(static_cast<const char*>(p), n); };
  for (const auto& r : d.runs) {
    out += r.run + '\0' + r.direction + '\0';
    for (const auto* v : {&r.t_s, &r.dist_left_m, &r.dist_right_m, &r.gt_x_m, &r.gt_y_m, &r.gt_theta_rad}) {
      add(v->data(), v->size() * sizeof(double));
      out += '|';
    }
    add(r.ticks_left.data(), r.ticks_left.size() * sizeof(std::int64_t));
    add(r.ticks_right.data(), r.ticks_right.size() * sizeof(std::int64_t));
    add(r.lines.data(), r.lines.size() * sizeof(std::size_t));
  }
  return out;
}

std::string ReadStreamed(std::string_view text, std::size_t chunk, std::size_t buffer) {
  try {
    umbmark::io::TrajectoryReader reader(text, "fuzz.csv", chunk, buffer);
    umbmark::TrajectoryData d;
    umbmark::TrajectoryRun run;
    while (reader.NextRun(run)) d.runs.push_back(run);  // run by run, reusing `run`
    return Fingerprint(d);
  } catch (const umbmark::InputError& e) {
    return std::string("error: ") + e.what();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    CheckEndpoint(umbmark::io::ParseEndpointCsv(text, "fuzz.csv"));
  } catch (const umbmark::InputError&) {
  }
  std::string whole;
  try {
    const umbmark::TrajectoryData d = umbmark::io::ParseTrajectoryCsv(text, "fuzz.csv");
    CheckTrajectory(d);
    whole = Fingerprint(d);
  } catch (const umbmark::InputError& e) {
    whole = std::string("error: ") + e.what();
  }
  const std::size_t chunk = size > 0 ? 1 + data[size - 1] % 7 : 1;
  const std::size_t buffer = size > 1 ? 1 + data[size - 2] % 5 : 1;
  Require(ReadStreamed(text, chunk, buffer) == whole);
  return 0;
}
