// Writers for trajectory and endpoint CSV and campaign manifests, and the
// whole campaign directory (see campaign_writer.hpp).
#include "formats/campaign_writer.hpp"

#include <cmath>
#include <filesystem>
#include <set>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/utf8.hpp"
#include "output/atomic_write.hpp"
#include "formats/csv_writer.hpp"

namespace umbmark::io {

namespace {
// TOML basic string: quotes, backslashes and control characters escaped
// (TOML 1.0, "String").
std::string TomlString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\b': out += "\\b"; break;
      case '\t': out += "\\t"; break;
      case '\n': out += "\\n"; break;
      case '\f': out += "\\f"; break;
      case '\r': out += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F)
          out += fmt::format("\\u{:04X}", static_cast<unsigned>(static_cast<unsigned char>(c)));
        else
          out += c;
    }
  }
  return out + "\"";
}

// The comment lines, each "# LINE\n". A comment holds user text (a folder
// name): bytes that are not UTF-8 are written as \xNN and control
// characters (a newline in a folder name would end the comment and leave
// the rest as TOML or CSV data) as \xNN too, so the file stays valid UTF-8
// TOML / CSV (TOML 1.0 forbids control characters other than tab in
// comments).
std::string CommentLines(const std::vector<std::string>& comment) {
  std::string out;
  for (const auto& line : comment) {
    out += "# ";
    for (const char c : EscapeInvalidUtf8(line)) {
      const auto u = static_cast<unsigned char>(c);
      if ((u < 0x20 && c != '\t') || u == 0x7F)
        out += fmt::format("\\x{:02X}", static_cast<unsigned>(u));
      else
        out += c;
    }
    out += "\n";
  }
  return out;
}
}  // namespace

std::string FormatTrajectoryCsv(const TrajectoryData& data, const std::vector<std::string>& comment) {
  std::string out = CommentLines(comment);
  const bool ticks = data.runs.empty() || data.runs.front().has_ticks();
  out += ticks ? "run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad\n"
               : "run,direction,t_s,dist_left_m,dist_right_m,x_gt_m,y_gt_m,theta_gt_rad\n";
  auto buf = fmt::memory_buffer();
  for (const auto& run : data.runs) {
    const std::string id = CsvField(run.run), dir = CsvField(run.direction);
    for (std::size_t i = 0; i < run.size(); ++i) {
      // "inf" or "nan" in a cell would make the file unreadable (readers
      // refuse them): refuse to write it instead.
      const bool finite = std::isfinite(run.t_s[i]) &&
                          (ticks || (std::isfinite(run.dist_left_m[i]) && std::isfinite(run.dist_right_m[i]))) &&
                          (!run.HasGroundTruth(i) || (std::isfinite(run.gt_x_m[i]) && std::isfinite(run.gt_y_m[i]) &&
                                                      std::isfinite(run.gt_theta_rad[i])));
      if (!finite) {
        throw InputError(data.path, fmt::format("run {} sample {}: a value is not finite (inf or NaN); nothing is "
                                                "written (an input or option far out of range?)",
                                                run.run, i + 1));
      }
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

// Written by hand rather than through toml++ (linked, used by the reader):
// toml++ 3.3 built with GCC prints doubles through a stream with 17
// significant digits (0.2 -> 0.20000000000000001, 2796.8 ->
// 2796.8000000000002; TOML_FLOAT_CHARCONV is 0 for GCC), its
// relaxed_float_precision flag prints 6 (0.08404612345678 -> 0.0840461: no
// round trip), it sorts keys (an experiment would start with `file`, not
// `kind`) and it writes no comments. fmt's {} gives the shortest digits
// that read back bit for bit (test_io_manifest_writer).
std::string FormatManifest(const Manifest& manifest, const std::vector<std::string>& comment,
                           const std::vector<ManifestKey>& ground_truth_keys) {
  std::string out = CommentLines(comment);
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
    for (const auto& k : ground_truth_keys) {
      if (const double* v = std::get_if<double>(&k.value)) out += fmt::format("{} = {}\n", k.key, *v);
      else out += k.key + " = " + TomlString(std::get<std::string>(k.value)) + "\n";
    }
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
  std::string out = CommentLines(comment);
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
                          bool replace, const std::vector<ManifestKey>& ground_truth_keys) {
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
    WriteFileAtomically((fs::path(staging) / "campaign.toml").string(), FormatManifest(manifest, comment, ground_truth_keys));
  } catch (...) {
    DiscardStagingDirectory(staging);
    throw;
  }
  CommitStagingDirectory(staging, dir, replace);
  return (fs::path(dir) / "campaign.toml").string();
}

}  // namespace umbmark::io
