// OptiOdom dataset importer (see optiodom.hpp).
#include "import/optiodom.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <vector>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "core/plausible_units.hpp"
#include "formats/file_text.hpp"

namespace umbmark::io {

namespace fs = std::filesystem;

namespace {

struct Cell {
  std::string text;
  std::size_t column;
};

// Splits text into lines of comma-separated cells with 1-based columns.
std::vector<std::vector<Cell>> SplitCsv(const std::string& text) {
  std::vector<std::vector<Cell>> rows;
  std::size_t pos = 0;
  if (text.size() >= 3 && text.compare(0, 3, "\xEF\xBB\xBF") == 0) pos = 3;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::vector<Cell> cells;
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = line.find(',', start);
      const std::size_t stop = comma == std::string::npos ? line.size() : comma;
      cells.push_back({line.substr(start, stop - start), start + 1});
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    rows.push_back(std::move(cells));
    pos = end + 1;
  }
  return rows;
}

double ParseNumber(const std::string& file, std::size_t line, const Cell& cell, const char* what) {
  double v = 0.0;
  const char* b = cell.text.data();
  const char* e = b + cell.text.size();
  auto [ptr, ec] = std::from_chars(b, e, v);
  if (cell.text.empty() || ec != std::errc() || ptr != e || !std::isfinite(v)) {
    throw InputError(file, line, cell.column, fmt::format("{}: '{}' is not a finite number", what, cell.text));
  }
  return v;
}

struct MetaValue {
  std::vector<Cell> values;  // non-empty cells after the key
  std::size_t line;
};

std::map<std::string, MetaValue> ReadMetadata(const std::string& path) {
  std::map<std::string, MetaValue> meta;
  const auto rows = SplitCsv(ReadWholeFile(path));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& row = rows[i];
    if (row.size() == 1 && row[0].text.empty()) continue;
    MetaValue v{{}, i + 1};
    for (std::size_t c = 1; c < row.size(); ++c)
      if (!row[c].text.empty()) v.values.push_back(row[c]);
    meta[row[0].text] = v;
  }
  return meta;
}

const MetaValue& Require(const std::map<std::string, MetaValue>& meta, const std::string& path,
                         const std::string& key, std::size_t count) {
  auto it = meta.find(key);
  if (it == meta.end()) throw InputError(path, fmt::format("metadata key '{}' is missing", key));
  if (it->second.values.size() < count) {
    throw InputError(path, it->second.line, 0,
                     fmt::format("metadata key '{}' needs {} value(s), has {}", key, count, it->second.values.size()));
  }
  return it->second;
}

TrajectoryRun ReadRun(const std::string& path, const std::string& id, const std::string& direction_hint) {
  TrajectoryRun run;
  run.run = id;
  run.direction = direction_hint;
  const auto rows = SplitCsv(ReadWholeFile(path));
  std::int64_t cum_l = 0, cum_r = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& row = rows[i];
    const std::size_t line = i + 1;
    if (row.size() == 1 && row[0].text.empty()) continue;
    if (row.size() != 6) {
      throw InputError(path, line, row.back().column,
                       fmt::format("expected 6 cells (time, x, y, theta, right ticks, left ticks), found {}", row.size()));
    }
    const double t = ParseNumber(path, line, row[0], "time");
    const double x = ParseNumber(path, line, row[1], "x_gt");
    const double y = ParseNumber(path, line, row[2], "y_gt");
    const double th = ParseNumber(path, line, row[3], "theta_gt");
    const double dr = ParseNumber(path, line, row[4], "right ticks");
    const double dl = ParseNumber(path, line, row[5], "left ticks");
    for (auto [v, c] : {std::pair{dr, &row[4]}, std::pair{dl, &row[5]}}) {
      if (v != std::round(v) || std::abs(v) > 1e12)
        throw InputError(path, line, c->column, fmt::format("tick increment '{}' is not a whole number", c->text));
    }
    if (!run.t_s.empty() && !(t > run.t_s.back()))
      throw InputError(path, line, row[0].column, fmt::format("time {} does not increase", row[0].text));
    // The first row's increments happened before the run started.
    if (!run.t_s.empty()) {
      cum_l += static_cast<std::int64_t>(dl);
      cum_r += static_cast<std::int64_t>(dr);
    }
    run.t_s.push_back(t);
    run.ticks_left.push_back(cum_l);
    run.ticks_right.push_back(cum_r);
    run.gt_x_m.push_back(x);
    run.gt_y_m.push_back(y);
    run.gt_theta_rad.push_back(th);
    run.lines.push_back(line);
  }
  if (run.t_s.size() < 2) throw InputError(path, "run has fewer than two samples");
  return run;
}

}  // namespace

namespace {

/// The metadata file and the run files (<id>_run-NN.csv, by NN) of a folder.
struct DatasetFiles {
  std::string metadata;
  std::vector<std::pair<int, std::string>> runs;
};

DatasetFiles ListDatasetFiles(const fs::path& folder, const std::string& dir) {
  DatasetFiles out;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (name.size() > 13 && name.ends_with("_metadata.csv")) {
      out.metadata = entry.path().string();
    } else if (const auto pos = name.rfind("_run-"); pos != std::string::npos && name.ends_with(".csv")) {
      // <id>_run-NN.csv
      const std::string digits = name.substr(pos + 5, name.size() - pos - 9);
      int number = 0;
      auto [ptr, err] = std::from_chars(digits.data(), digits.data() + digits.size(), number);
      if (!digits.empty() && err == std::errc() && ptr == digits.data() + digits.size())
        out.runs.emplace_back(number, entry.path().string());
    }
  }
  if (out.metadata.empty()) throw InputError(dir, "no <id>_metadata.csv in the folder");
  if (out.runs.empty()) throw InputError(dir, "no <id>_run-NN.csv files in the folder");
  std::sort(out.runs.begin(), out.runs.end());
  return out;
}

/// square, circular, ivanjko or free: as given, else the parent folder's
/// name when it is one of those, else square when the metadata give a side.
std::string DatasetCategory(const fs::path& folder, const std::optional<std::string>& category, bool has_side) {
  if (category) return *category;
  const std::string parent = folder.parent_path().filename().string();
  if (parent == "square" || parent == "circular" || parent == "ivanjko" || parent == "free") return parent;
  return has_side ? "square" : "free";
}

/// cw or ccw from the ground truth's total rotation (sum of wrapped
/// increments; theta_gt is unwrapped in these files, either works).
std::string SquareDirection(const TrajectoryRun& run, const std::string& path) {
  double total = 0.0;
  for (std::size_t i = 1; i < run.size(); ++i) total += WrapAngle(run.gt_theta_rad[i] - run.gt_theta_rad[i - 1]);
  if (std::abs(std::abs(total) - 2.0 * kPi) > kPi / 2.0) {
    throw InputError(path, fmt::format("ground truth turns {:.1f} deg in total; a square run turns about +-360 deg",
                                       Rad2Deg(total)));
  }
  return total < 0.0 ? "cw" : "ccw";
}

}  // namespace

OptiOdomDataset ImportOptiOdom(const std::string& dir, const std::optional<std::string>& category) {
  fs::path folder = fs::path(dir).lexically_normal();
  if (folder.filename().empty()) folder = folder.parent_path();  // "DIR/" -> "DIR"
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw InputError(dir, "not a directory");
  OptiOdomDataset ds;
  ds.id = folder.filename().string();
  const DatasetFiles files = ListDatasetFiles(folder, dir);
  const std::string& meta_path = files.metadata;

  const auto meta = ReadMetadata(meta_path);
  auto number = [&](const std::string& key, std::size_t idx) {
    const auto& v = Require(meta, meta_path, key, idx + 1);
    return ParseNumber(meta_path, v.line, v.values[idx], key.c_str());
  };
  // A value outside its plausible range (core/plausible_units.hpp: a
  // negative side, a wheelbase in millimetres) is refused at its cell rather
  // than written into the campaign.
  auto plausible = [&](const std::string& key, std::size_t idx, std::string_view range) {
    const double x = number(key, idx);
    if (auto why = ImplausibleValue(range, x); !why.empty()) {
      const auto& v = Require(meta, meta_path, key, idx + 1);
      throw InputError(meta_path, v.line, v.values[idx].column, fmt::format("{}: {}", key, why));
    }
    return x;
  };
  const double ngear = number("ngear", 0), enc = number("encRes", 0);
  ds.robot.wheelbase_m = plausible("Li", 0, "wheelbase_m");
  ds.robot.wheel_diameter_right_m = plausible("Di", 0, "wheel_diameter_right_m");  // Di = [right, left]
  ds.robot.wheel_diameter_left_m = plausible("Di", 1, "wheel_diameter_left_m");
  ds.robot.ticks_per_rev = ngear * enc;
  if (auto err = ds.robot.Check(); !err.empty()) throw InputError(meta_path, "robot parameters: " + err);

  std::optional<double> side;
  if (auto it = meta.find("L"); it != meta.end() && !it->second.values.empty()) side = plausible("L", 0, "side_m");
  if (auto it = meta.find("N"); it != meta.end() && !it->second.values.empty()) {
    const double n = number("N", 0);
    if (n != static_cast<double>(files.runs.size())) {
      throw InputError(meta_path, it->second.line, it->second.values[0].column,
                       fmt::format("N = {} but the folder has {} run files", n, files.runs.size()));
    }
  }

  ds.category = DatasetCategory(folder, category, side.has_value());
  const bool square = ds.category == "square";
  if (square && !side) throw InputError(meta_path, "square dataset without a side length L");
  ds.experiment.kind = square ? ExperimentKind::kSquare : ExperimentKind::kFree;
  ds.experiment.side_m = square ? *side : 0.0;
  ds.experiment.file = "runs.csv";
  ds.runs.path = (folder / "runs.csv").string();
  for (const auto& [num, path] : files.runs) {
    TrajectoryRun run = ReadRun(path, std::to_string(num), ds.category);
    if (square) run.direction = SquareDirection(run, path);
    ds.runs.runs.push_back(std::move(run));
  }
  return ds;
}

}  // namespace umbmark::io
