// Fleet summary with robust z-scores (see fleet.hpp).
#include "calibration/fleet.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace umbmark {

const char* FleetQuantityKey(FleetQuantity q) {
  switch (q) {
    case FleetQuantity::kWheelbase: return "wheelbase_m";
    case FleetQuantity::kDiameterLeft: return "wheel_diameter_left_m";
    case FleetQuantity::kDiameterRight: return "wheel_diameter_right_m";
    case FleetQuantity::kEd: return "E_d";
    case FleetQuantity::kEb: return "E_b";
    case FleetQuantity::kEmaxBefore: return "E_max_syst_m";
    case FleetQuantity::kResidualAfter: return "residual_after_m";
  }
  return "?";
}

bool FleetQuantityIsRelative(FleetQuantity q) {
  return q == FleetQuantity::kEd || q == FleetQuantity::kEb || q == FleetQuantity::kEmaxBefore;
}

std::string FleetRecordedKey(double wheelbase_m, double diameter_left_m, double diameter_right_m) {
  return fmt::format("{:.9g},{:.9g},{:.9g}", wheelbase_m, diameter_left_m, diameter_right_m);
}

std::string FleetOptions::Check() const {
  if (!(threshold > 0.0)) return fmt::format("threshold = {} must be > 0", threshold);
  if (!(min_relative_spread >= 0.0)) return fmt::format("min_relative_spread = {} must be >= 0", min_relative_spread);
  return "";
}

namespace {
double Median(std::vector<double> v) {
  const std::size_t n = v.size();
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2), v.end());
  const double hi = v[n / 2];
  if (n % 2 == 1) return hi;
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2)));
}

// What a robot standing out in one quantity usually means on a factory line.
std::string Reason(FleetQuantity q, double value, double z, const FleetStat& s) {
  const char* dir = z > 0 ? "above" : "below";
  auto mm = [](double m) { return fmt::format("{:.2f} mm", m * 1e3); };
  switch (q) {
    case FleetQuantity::kDiameterLeft:
    case FleetQuantity::kDiameterRight: {
      const char* side = q == FleetQuantity::kDiameterLeft ? "left" : "right";
      return fmt::format("{} wheel diameter {:.5f} m is {:.1f} robust SD {} the fleet median {:.5f} m ({:+.2f}%): {}", side,
                         value, std::abs(z), dir, s.median, 100.0 * (value / s.median - 1.0),
                         z < 0 ? "a worn or wrong wheel/tyre" : "a wrong wheel/tyre or under-inflated contact");
    }
    case FleetQuantity::kWheelbase:
      return fmt::format("wheelbase {:.5f} m is {:.1f} robust SD {} the fleet median {:.5f} m ({:+.2f}%): wheels mounted "
                         "at the wrong track (mis-assembled) or a different tyre contact",
                         value, std::abs(z), dir, s.median, 100.0 * (value / s.median - 1.0));
    case FleetQuantity::kEd:
      return fmt::format("diameter ratio E_d {:.5f} is {:.1f} robust SD {} the fleet median {:.5f}: one wheel differs "
                         "from the other (wearing or wrong wheel)",
                         value, std::abs(z), dir, s.median);
    case FleetQuantity::kEb:
      return fmt::format("wheelbase error E_b {:.5f} is {:.1f} robust SD {} the fleet median {:.5f}: the effective "
                         "track differs (mis-assembled axle or wheel mount)",
                         value, std::abs(z), dir, s.median);
    case FleetQuantity::kEmaxBefore:
      return fmt::format("systematic error before calibration E_max,syst {} is {:.1f} robust SD {} the fleet median {}",
                         mm(value), std::abs(z), dir, mm(s.median));
    case FleetQuantity::kResidualAfter:
      return fmt::format("error left after correction {} is {:.1f} robust SD {} the fleet median {}: the calibration "
                         "does not fit this robot (slipping wheel, loose castor); run `umbmark diagnose` on its runs",
                         mm(value), std::abs(z), dir, mm(s.median));
  }
  return "";
}

/// The value of `q` of robot `r`, when it has a finite one.
const double* ValueOf(const FleetRobot& r, FleetQuantity q) {
  const auto it = r.values.find(q);
  return it != r.values.end() && std::isfinite(it->second) ? &it->second : nullptr;
}

/// Median and robust spread of `q` over the robots `members` that give it.
FleetStat StatOf(const std::vector<FleetRobot>& robots, const std::vector<std::size_t>& members, FleetQuantity q,
                 const FleetOptions& options) {
  std::vector<double> v;
  for (std::size_t i : members)
    if (const double* x = ValueOf(robots[i], q)) v.push_back(*x);
  FleetStat s;
  s.n = v.size();
  if (v.empty()) return s;
  s.median = Median(v);
  std::vector<double> dev;
  for (double x : v) dev.push_back(std::abs(x - s.median));
  s.mad = 1.4826 * Median(dev);
  s.spread = std::max(s.mad, options.min_relative_spread * std::abs(s.median));
  return s;
}

/// Robust z-scores of `q` for the robots `members` against their own stat.
void Score(const std::vector<FleetRobot>& robots, const std::vector<std::size_t>& members, FleetQuantity q,
           const FleetOptions& options, FleetSummary& out) {
  const FleetStat s = StatOf(robots, members, q, options);
  if (s.n < 3 || !(s.spread > 0.0)) return;
  for (std::size_t i : members) {
    const double* x = ValueOf(robots[i], q);
    if (x == nullptr) continue;
    out.robots[i].z[q] = (*x - s.median) / s.spread;
    out.robots[i].reference[q] = s;
  }
}
}  // namespace

FleetSummary SummarizeFleet(const std::vector<FleetRobot>& robots, const FleetOptions& options) {
  FleetSummary out;
  out.robots.resize(robots.size());
  std::vector<std::size_t> all(robots.size());
  for (std::size_t i = 0; i < robots.size(); ++i) all[i] = i;
  std::map<std::string, std::vector<std::size_t>> groups;  // recorded parameters -> robots
  for (std::size_t i = 0; i < robots.size(); ++i) groups[robots[i].recorded].push_back(i);
  out.groups = groups.size();
  for (FleetQuantity q : kFleetQuantities) {
    const FleetStat s = StatOf(robots, all, q, options);
    if (s.n == 0) continue;
    out.fleet[q] = s;
    if (!FleetQuantityIsRelative(q)) {
      Score(robots, all, q, options, out);
      continue;
    }
    for (const auto& [key, members] : groups) Score(robots, members, q, options, out);
  }
  for (std::size_t i = 0; i < robots.size(); ++i) {
    auto& r = out.robots[i];
    std::vector<std::pair<double, FleetQuantity>> flagged;
    for (const auto& [q, z] : r.z)
      if (std::abs(z) > options.threshold) flagged.emplace_back(std::abs(z), q);
    std::sort(flagged.begin(), flagged.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    for (const auto& [az, q] : flagged) r.reasons.push_back(Reason(q, robots[i].values.at(q), r.z.at(q), r.reference.at(q)));
    r.outlier = !flagged.empty();
  }
  return out;
}

}  // namespace umbmark
