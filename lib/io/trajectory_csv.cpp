// Trajectory CSV reader (contract: run,direction,t_s,ticks_left,ticks_right,
// x_gt_m,y_gt_m,theta_gt_rad, or dist_left_m,dist_right_m instead of ticks).
// Built for large logs: one pass over text in memory, no allocation per cell,
// strings allocated only when a run starts.
#include "io/trajectory_csv.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <unordered_map>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "io/file_text.hpp"
#include "io/csv_table.hpp"

namespace umbmark::io {
namespace {

using detail::ColumnSpec;
using detail::CsvReader;
using detail::Quantity;
using detail::QuoteForMessage;
using detail::ResolvedColumn;

enum Col : std::size_t { kRun, kDirection, kT, kTicksL, kTicksR, kDistL, kDistR, kXGt, kYGt, kThetaGt };

constexpr ColumnSpec kSpecs[] = {
    {"run", Quantity::kText},         {"direction", Quantity::kText},   {"t", Quantity::kTime},
    {"ticks_left", Quantity::kCount}, {"ticks_right", Quantity::kCount}, {"dist_left", Quantity::kLength},
    {"dist_right", Quantity::kLength}, {"x_gt", Quantity::kLength},      {"y_gt", Quantity::kLength},
    {"theta_gt", Quantity::kAngle},
};

/// Two consecutive cumulative counts further apart than this can only be a
/// counter that wrapped (or garbage): at 2^30 ticks even a 2^20-tick-per-rev
/// encoder would have turned 1000 revolutions between two samples.
constexpr std::int64_t kMaxTickJump = std::int64_t{1} << 30;

const char* MissingName(Col c) {
  switch (c) {
    case kRun: return "run";
    case kDirection: return "direction";
    case kT: return "t_s";
    case kTicksL: return "ticks_left";
    case kTicksR: return "ticks_right";
    case kDistL: return "dist_left_m";
    case kDistR: return "dist_right_m";
    case kXGt: return "x_gt_m";
    case kYGt: return "y_gt_m";
    case kThetaGt: return "theta_gt_rad";
  }
  return "?";
}

void CheckTickJump(const CsvReader& csv, const ResolvedColumn& c, std::int64_t previous, std::int64_t current) {
  std::int64_t delta = 0;
  if (__builtin_sub_overflow(current, previous, &delta)) {
    csv.FailCell(c.index, fmt::format("{} jumps by more than 2^63 ticks (from {} to {}): counter wrap-around?",
                                      c.header, previous, current));
  }
  if (delta >= kMaxTickJump || delta <= -kMaxTickJump) {
    csv.FailCell(c.index, fmt::format("{} jumps by {} ticks: counter wrap-around?", c.header, delta));
  }
}

}  // namespace

TrajectoryData ParseTrajectoryCsv(std::string_view text, const std::string& name) {
  CsvReader csv(text, name);
  const std::vector<ResolvedColumn> cols = csv.Resolve(kSpecs);

  const bool ticks = cols[kTicksL].present() || cols[kTicksR].present();
  const bool dist = cols[kDistL].present() || cols[kDistR].present();
  if (ticks && dist) {
    csv.FailLine(csv.header_line(), "header gives both ticks_* and dist_*_m columns; give one of the two");
  }
  std::vector<Col> required = {kRun, kDirection, kT};
  if (dist) {
    required.insert(required.end(), {kDistL, kDistR});
  } else {
    required.insert(required.end(), {kTicksL, kTicksR});
  }
  required.insert(required.end(), {kXGt, kYGt, kThetaGt});
  for (const Col c : required) {
    if (!cols[c].present()) {
      csv.FailLine(csv.header_line(),
                   fmt::format("missing column '{}'{}", MissingName(c),
                               c == kTicksL || c == kTicksR ? " (or give dist_left_m,dist_right_m)" : ""));
    }
  }
  if (csv.HasNoDataRows()) csv.FailFile("no data rows after the header");

  const ResolvedColumn& c_run = cols[kRun];
  const ResolvedColumn& c_dir = cols[kDirection];
  const ResolvedColumn& c_t = cols[kT];
  const ResolvedColumn& c_left = cols[ticks ? kTicksL : kDistL];
  const ResolvedColumn& c_right = cols[ticks ? kTicksR : kDistR];
  const ResolvedColumn* c_gt[3] = {&cols[kXGt], &cols[kYGt], &cols[kThetaGt]};

  TrajectoryData data;
  data.path = name;
  TrajectoryRun* run = nullptr;
  // Run id -> last line of its (finished) block, to reject a run split in two.
  std::unordered_map<std::string, std::size_t> finished;
  // Where the current run's last sample is, to report missing ground truth there.
  std::size_t last_line = 0;
  const char* last_row = nullptr;
  const char* last_gt_cell = nullptr;
  bool last_has_gt = false;
  std::size_t previous_size = 0;

  const auto finish_run = [&] {
    if (run == nullptr) return;
    if (!last_has_gt) {
      csv.FailAt(last_line, CsvReader::ColumnIn(last_row, last_gt_cell),
                 fmt::format("run {} has no ground truth at its last sample (each run needs {}, {}, {} at its "
                             "first and last sample)",
                             QuoteForMessage(run->run), c_gt[0]->header, c_gt[1]->header, c_gt[2]->header));
    }
    finished.emplace(run->run, last_line);
    previous_size = run->size();
    // Give back a reserve that was far too generous (the first run's guess
    // from the file size); a close fit is kept, so a single big run is never
    // copied.
    if (run->t_s.capacity() > 2 * run->size() + 1024) {
      for (auto* v : {&run->t_s, &run->dist_left_m, &run->dist_right_m, &run->gt_x_m, &run->gt_y_m,
                      &run->gt_theta_rad}) {
        v->shrink_to_fit();
      }
      run->ticks_left.shrink_to_fit();
      run->ticks_right.shrink_to_fit();
      run->lines.shrink_to_fit();
    }
  };

  while (csv.Next()) {
    // Run id and direction are validated (Text) when a run starts; later rows
    // only compare them with the run's, which they must equal.
    std::string_view run_id = csv.cell(c_run.index);
    std::string_view direction = csv.cell(c_dir.index);
    if (run == nullptr || run_id != run->run) {
      run_id = csv.Text(c_run);
      direction = csv.Text(c_dir);
      finish_run();
      if (const auto it = finished.find(std::string(run_id)); it != finished.end()) {
        csv.FailCell(c_run.index, fmt::format("run {} appears again after run {}: the rows of a run must be "
                                              "contiguous (its first block ended on line {})",
                                              QuoteForMessage(run_id), QuoteForMessage(run->run), it->second));
      }
      run = &data.runs.emplace_back();
      run->run = std::string(run_id);
      run->direction = std::string(direction);
      // Runs of one file tend to be alike in length; the first gets a size
      // estimated from the file (untouched capacity costs no memory).
      const std::size_t reserve = data.runs.size() == 1 ? std::min<std::size_t>(csv.EstimatedRows(), 1u << 24)
                                                        : previous_size + previous_size / 8 + 16;
      run->t_s.reserve(reserve);
      run->lines.reserve(reserve);
      if (ticks) {
        run->ticks_left.reserve(reserve);
        run->ticks_right.reserve(reserve);
      } else {
        run->dist_left_m.reserve(reserve);
        run->dist_right_m.reserve(reserve);
      }
      run->gt_x_m.reserve(reserve);
      run->gt_y_m.reserve(reserve);
      run->gt_theta_rad.reserve(reserve);
    } else if (direction != run->direction) {
      direction = csv.Text(c_dir);
      csv.FailCell(c_dir.index, fmt::format("direction changes from {} to {} within run {} (a run keeps one direction; give "
                                            "each run its own id)",
                                            QuoteForMessage(run->direction), QuoteForMessage(direction),
                                            QuoteForMessage(run->run)));
    }

    const double t = csv.Number(c_t);
    if (!run->t_s.empty() && !(t > run->t_s.back())) {
      csv.FailCell(c_t.index, fmt::format("{} = {} does not increase (previous sample of run {}, line {}, has {})",
                                          c_t.header, csv.cell(c_t.index), QuoteForMessage(run->run),
                                          run->lines.back(), run->t_s.back()));
    }
    if (ticks) {
      const std::int64_t left = csv.Count(c_left);
      const std::int64_t right = csv.Count(c_right);
      if (!run->ticks_left.empty()) {
        CheckTickJump(csv, c_left, run->ticks_left.back(), left);
        CheckTickJump(csv, c_right, run->ticks_right.back(), right);
      }
      run->ticks_left.push_back(left);
      run->ticks_right.push_back(right);
    } else {
      run->dist_left_m.push_back(csv.Number(c_left));
      run->dist_right_m.push_back(csv.Number(c_right));
    }

    double gt[3] = {0.0, 0.0, 0.0};
    bool has[3] = {false, false, false};
    for (int k = 0; k < 3; ++k) has[k] = csv.OptionalNumber(*c_gt[k], gt[k]);
    const bool has_gt = has[0] && has[1] && has[2];
    if (!has_gt && (has[0] || has[1] || has[2])) {
      const int empty = !has[0] ? 0 : !has[1] ? 1 : 2;
      const int given = has[0] ? 0 : has[1] ? 1 : 2;
      csv.FailCell(c_gt[empty]->index,
                   fmt::format("partial ground truth: {} is empty while {} is given (give all three or none)",
                               c_gt[empty]->header, c_gt[given]->header));
    }
    if (!has_gt && run->t_s.empty()) {
      csv.FailCell(c_gt[0]->index,
                   fmt::format("run {} has no ground truth at its first sample (each run needs {}, {}, {} at its "
                               "first and last sample)",
                               QuoteForMessage(run->run), c_gt[0]->header, c_gt[1]->header, c_gt[2]->header));
    }
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    run->gt_x_m.push_back(has_gt ? gt[0] : kNaN);
    run->gt_y_m.push_back(has_gt ? gt[1] : kNaN);
    run->gt_theta_rad.push_back(has_gt ? gt[2] : kNaN);
    run->t_s.push_back(t);
    run->lines.push_back(csv.line());

    last_line = csv.line();
    last_row = csv.row_begin();
    last_gt_cell = csv.cell(c_gt[0]->index).data();
    last_has_gt = has_gt;
  }
  finish_run();
  return data;
}

TrajectoryData ReadTrajectoryCsv(const std::string& path) {
  const detail::FileText text(path);
  return ParseTrajectoryCsv(text.view(), path);
}

}  // namespace umbmark::io
