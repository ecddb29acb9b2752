// Writers for trajectory and endpoint CSV and campaign manifests, and the
// whole campaign directory (see campaign_writer.hpp).
#include "io/campaign_writer.hpp"

#include <cmath>
#include <filesystem>
#include <set>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "io/atomic_write.hpp"
#include "io/csv_writer.hpp"

namespace umbmark::io {

namespace {
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
    const std::string id = CsvField(run.run), dir = CsvField(run.direction);
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

std::string FormatEndpointCsv(const EndpointData& data, const std::vector<std::string>& comment) {
  std::string out;
  for (const auto& line : comment) out += "# " + line + "\n";
  out += "run,direction,ex_m,ey_m,etheta_rad\n";
  for (const auto& r : data.runs) {
    out += fmt::format("{},{},{},{},", CsvField(r.run), CsvField(r.direction), r.ex_m, r.ey_m);
    if (r.etheta_rad) out += fmt::format("{}", *r.etheta_rad);
    out += "\n";
  }
  return out;
}

std::string WriteCampaign(const Manifest& manifest, const std::vector<ExperimentData>& data, const std::string& dir,
                          const std::vector<std::string>& comment, const std::vector<ExtraFile>& extra_files,
                          bool replace) {
  namespace fs = std::filesystem;
  if (data.size() != manifest.experiments.size())
    throw InputError(manifest.path, fmt::format("{} experiments but {} data sets to write", manifest.experiments.size(), data.size()));
  std::set<std::string> names = {"campaign.toml"};
  for (std::size_t e = 0; e < manifest.experiments.size(); ++e) {
    const std::string& file = manifest.experiments[e].file;
    const fs::path rel = fs::path(file).lexically_normal();
    if (rel.is_absolute() || rel.empty() || *rel.begin() == "..")
      throw InputError(manifest.path,
                       fmt::format("experiment {}: file '{}' must be a relative path inside the output directory",
                                   e + 1, file));
    if (!names.insert(rel.string()).second)
      throw InputError(manifest.path,
                       fmt::format("experiment {}: file '{}' is used twice (or is campaign.toml)", e + 1, file));
  }
  for (const auto& x : extra_files) {
    if (!names.insert(fs::path(x.name).lexically_normal().string()).second)
      throw InputError(dir, fmt::format("'{}' would be written twice", x.name));
  }
  std::error_code ec;
  const fs::path parent = fs::absolute(dir).lexically_normal().parent_path();
  fs::create_directories(parent, ec);
  if (ec || !fs::is_directory(parent)) throw InputError(dir, "cannot create the parent folder: " + ec.message());
  // The whole campaign goes into a staging folder next to `dir`, renamed
  // into place in one step: a reader (or an interrupted run) sees the
  // complete old campaign or the complete new one, never a mix.
  const std::string staging = MakeStagingDirectory(dir);
  try {
    for (std::size_t e = 0; e < manifest.experiments.size(); ++e) {
      const fs::path target = fs::path(staging) / fs::path(manifest.experiments[e].file).lexically_normal();
      if (target.parent_path() != fs::path(staging)) CreateStagedFolder(target.parent_path().string());
      const auto& d = data[e];
      if (const auto* t = std::get_if<TrajectoryData>(&d))
        WriteFileAtomically(target.string(), FormatTrajectoryCsv(*t, comment));
      else
        WriteFileAtomically(target.string(), FormatEndpointCsv(std::get<EndpointData>(d), comment));
    }
    for (const auto& x : extra_files) WriteFileAtomically((fs::path(staging) / x.name).string(), x.content);
    WriteFileAtomically((fs::path(staging) / "campaign.toml").string(), FormatManifest(manifest, comment));
  } catch (...) {
    DiscardStagingDirectory(staging);
    throw;
  }
  CommitStagingDirectory(staging, dir, replace);
  return (fs::path(dir) / "campaign.toml").string();
}

}  // namespace umbmark::io
