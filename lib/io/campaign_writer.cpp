// Writers for trajectory CSV and campaign manifests (see campaign_writer.hpp).
#include "io/campaign_writer.hpp"

#include <cmath>

#include <fmt/format.h>

namespace umbmark::io {

namespace {
// CSV cell for free text: the contract has no quoting, so commas and line
// breaks are replaced rather than emitted.
std::string CleanCell(std::string s) {
  for (char& c : s)
    if (c == ',' || c == '\n' || c == '\r') c = ' ';
  return s;
}

std::string TomlString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}
}  // namespace

std::string FormatTrajectoryCsv(const TrajectoryData& data, const std::vector<std::string>& comment) {
  std::string out;
  for (const auto& line : comment) out += "# " + line + "\n";
  const bool ticks = data.runs.empty() || data.runs.front().has_ticks();
  out += ticks ? "run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad\n"
               : "run,direction,t_s,dist_left_m,dist_right_m,x_gt_m,y_gt_m,theta_gt_rad\n";
  auto buf = fmt::memory_buffer();
  for (const auto& run : data.runs) {
    const std::string id = CleanCell(run.run), dir = CleanCell(run.direction);
    for (std::size_t i = 0; i < run.size(); ++i) {
      fmt::format_to(std::back_inserter(buf), "{},{},{},", id, dir, run.t_s[i]);
      if (ticks)
        fmt::format_to(std::back_inserter(buf), "{},{},", run.ticks_left[i], run.ticks_right[i]);
      else
        fmt::format_to(std::back_inserter(buf), "{},{},", run.dist_left_m[i], run.dist_right_m[i]);
      if (run.HasGroundTruth(i))
        fmt::format_to(std::back_inserter(buf), "{},{},{}\n", run.gt_x_m[i], run.gt_y_m[i], run.gt_theta_rad[i]);
      else
        fmt::format_to(std::back_inserter(buf), ",,\n");
    }
  }
  out.append(buf.data(), buf.size());
  return out;
}

std::string FormatManifest(const Manifest& manifest, const std::vector<std::string>& comment) {
  std::string out;
  for (const auto& line : comment) out += "# " + line + "\n";
  const RobotParams& r = manifest.robot;
  out += "[robot]\n";
  out += fmt::format("wheelbase_m = {}\n", r.wheelbase_m);
  out += fmt::format("wheel_diameter_left_m = {}\n", r.wheel_diameter_left_m);
  out += fmt::format("wheel_diameter_right_m = {}\n", r.wheel_diameter_right_m);
  if (r.ticks_per_rev) out += fmt::format("ticks_per_rev = {}\n", *r.ticks_per_rev);
  if (manifest.ground_truth) {
    out += "\n[ground_truth]\n";
    out += fmt::format("sigma_xy_m = {}\n", manifest.ground_truth->sigma_xy_m);
    out += fmt::format("sigma_theta_rad = {}\n", manifest.ground_truth->sigma_theta_rad);
  }
  for (const auto& e : manifest.experiments) {
    out += "\n[[experiment]]\n";
    out += fmt::format("kind = \"{}\"\n", ExperimentKindToString(e.kind));
    if (e.kind == ExperimentKind::kSquare) out += fmt::format("side_m = {}\n", e.side_m);
    if (e.kind == ExperimentKind::kBackAndForth) out += fmt::format("distance_m = {}\n", e.distance_m);
    out += "file = " + TomlString(e.file) + "\n";
  }
  return out;
}

}  // namespace umbmark::io
