// Trajectory CSV reader (contract: run,direction,t_s,ticks_left,ticks_right,
// x_gt_m,y_gt_m,theta_gt_rad, or dist_left_m,dist_right_m instead of ticks).
// Built for large logs: streams through the tokenizer one row at a time, no
// allocation per cell, strings allocated only when a run starts, one run in
// memory at a time (plus the one the caller holds).
#include "formats/trajectory_csv.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <unordered_map>
#include <utility>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "formats/file_text.hpp"
#include "formats/csv_table.hpp"

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

struct TrajectoryReader::State {
  std::unique_ptr<CsvReader> csv;
  std::vector<ResolvedColumn> cols;
  bool ticks = false;
  const ResolvedColumn* c_run = nullptr;
  const ResolvedColumn* c_dir = nullptr;
  const ResolvedColumn* c_t = nullptr;
  const ResolvedColumn* c_left = nullptr;
  const ResolvedColumn* c_right = nullptr;
  const ResolvedColumn* c_gt[3] = {nullptr, nullptr, nullptr};

  TrajectoryRun current;  ///< the run being read
  bool have_current = false;
  /// Run id -> last line of its (finished) block, to reject a run split in two.
  std::unordered_map<std::string, std::size_t> finished;
  // Where the current run's last sample is, to report missing ground truth there.
  std::size_t last_line = 0;
  std::size_t last_gt_column = 0;
  bool last_has_gt = false;
  std::size_t previous_size = 0;

  explicit State(std::unique_ptr<CsvReader> reader);
  void FinishRun();
  /// A run id seen before (in an earlier block) is an error naming both lines.
  void CheckNewId(std::string_view run_id) const;
  /// Makes `current` an empty run with this id (keeping vector capacity).
  void StartRun(std::string_view run_id, std::string_view direction);
  void AddRow();
};

TrajectoryReader::State::State(std::unique_ptr<CsvReader> reader) : csv(std::move(reader)) {
  cols = csv->Resolve(kSpecs);
  ticks = cols[kTicksL].present() || cols[kTicksR].present();
  const bool dist = cols[kDistL].present() || cols[kDistR].present();
  if (ticks && dist) {
    csv->FailLine(csv->header_line(), "header gives both ticks_* and dist_*_m columns; give one of the two");
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
      csv->FailLine(csv->header_line(),
                    fmt::format("missing column '{}'{}", MissingName(c),
                                c == kTicksL || c == kTicksR ? " (or give dist_left_m,dist_right_m)" : ""));
    }
  }
  if (csv->HasNoDataRows()) csv->FailFile("no data rows after the header");
  c_run = &cols[kRun];
  c_dir = &cols[kDirection];
  c_t = &cols[kT];
  c_left = &cols[ticks ? kTicksL : kDistL];
  c_right = &cols[ticks ? kTicksR : kDistR];
  c_gt[0] = &cols[kXGt];
  c_gt[1] = &cols[kYGt];
  c_gt[2] = &cols[kThetaGt];
}

void TrajectoryReader::State::FinishRun() {
  if (!last_has_gt) {
    csv->FailAt(last_line, last_gt_column,
                fmt::format("run {} has no ground truth at its last sample (each run needs {}, {}, {} at its "
                            "first and last sample)",
                            QuoteForMessage(current.run), c_gt[0]->header, c_gt[1]->header, c_gt[2]->header));
  }
  finished.emplace(current.run, last_line);
  previous_size = current.size();
}

void TrajectoryReader::State::CheckNewId(std::string_view run_id) const {
  if (const auto it = finished.find(std::string(run_id)); it != finished.end()) {
    csv->FailCell(c_run->index, fmt::format("run {} appears again after run {}: the rows of a run must be "
                                            "contiguous (its first block ended on line {})",
                                            QuoteForMessage(run_id), QuoteForMessage(current.run), it->second));
  }
}

void TrajectoryReader::State::StartRun(std::string_view run_id, std::string_view direction) {
  TrajectoryRun& r = current;
  r.run.assign(run_id);
  r.direction = CanonicalDirection(direction);
  for (auto* v : {&r.t_s, &r.dist_left_m, &r.dist_right_m, &r.gt_x_m, &r.gt_y_m, &r.gt_theta_rad}) v->clear();
  r.ticks_left.clear();
  r.ticks_right.clear();
  r.lines.clear();
  // Runs of one file tend to be alike in length: a long run reserves the
  // previous one's size (short ones grow by doubling, which costs little).
  if (previous_size > 4096) {
    const std::size_t reserve = previous_size + previous_size / 8;
    r.t_s.reserve(reserve);
    r.lines.reserve(reserve);
    if (ticks) {
      r.ticks_left.reserve(reserve);
      r.ticks_right.reserve(reserve);
    } else {
      r.dist_left_m.reserve(reserve);
      r.dist_right_m.reserve(reserve);
    }
    r.gt_x_m.reserve(reserve);
    r.gt_y_m.reserve(reserve);
    r.gt_theta_rad.reserve(reserve);
  }
}

void TrajectoryReader::State::AddRow() {
  TrajectoryRun& run = current;
  const CsvReader& in = *csv;
  const double t = in.Number(*c_t);
  if (!run.t_s.empty() && !(t > run.t_s.back())) {
    in.FailCell(c_t->index, fmt::format("{} = {} does not increase (previous sample of run {}, line {}, has {})",
                                        c_t->header, in.cell(c_t->index), QuoteForMessage(run.run),
                                        run.lines.back(), run.t_s.back()));
  }
  if (ticks) {
    const std::int64_t left = in.Count(*c_left);
    const std::int64_t right = in.Count(*c_right);
    if (!run.ticks_left.empty()) {
      CheckTickJump(in, *c_left, run.ticks_left.back(), left);
      CheckTickJump(in, *c_right, run.ticks_right.back(), right);
    }
    run.ticks_left.push_back(left);
    run.ticks_right.push_back(right);
  } else {
    run.dist_left_m.push_back(in.Number(*c_left));
    run.dist_right_m.push_back(in.Number(*c_right));
  }

  double gt[3] = {0.0, 0.0, 0.0};
  bool has[3] = {false, false, false};
  for (int k = 0; k < 3; ++k) has[k] = in.OptionalNumber(*c_gt[k], gt[k]);
  const bool has_gt = has[0] && has[1] && has[2];
  if (!has_gt && (has[0] || has[1] || has[2])) {
    const int empty = !has[0] ? 0 : !has[1] ? 1 : 2;
    const int given = has[0] ? 0 : has[1] ? 1 : 2;
    in.FailCell(c_gt[empty]->index,
                fmt::format("partial ground truth: {} is empty while {} is given (give all three or none)",
                            c_gt[empty]->header, c_gt[given]->header));
  }
  if (!has_gt && run.t_s.empty()) {
    in.FailCell(c_gt[0]->index,
                fmt::format("run {} has no ground truth at its first sample (each run needs {}, {}, {} at its "
                            "first and last sample)",
                            QuoteForMessage(run.run), c_gt[0]->header, c_gt[1]->header, c_gt[2]->header));
  }
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  run.gt_x_m.push_back(has_gt ? gt[0] : kNaN);
  run.gt_y_m.push_back(has_gt ? gt[1] : kNaN);
  run.gt_theta_rad.push_back(has_gt ? gt[2] : kNaN);
  run.t_s.push_back(t);
  run.lines.push_back(in.line());

  last_line = in.line();
  last_has_gt = has_gt;
  // The row is gone once the next is read: keep the column a missing
  // ground truth at the run's end would be reported at.
  if (!has_gt) last_gt_column = in.Column(c_gt[0]->index);
}

TrajectoryReader::TrajectoryReader(std::unique_ptr<detail::CsvReader> csv)
    : state_(std::make_unique<State>(std::move(csv))) {}

TrajectoryReader::TrajectoryReader(const TrajectoryReader& header_from, std::uint64_t begin, std::uint64_t end,
                                   std::size_t first_line)
    : TrajectoryReader(std::make_unique<CsvReader>(detail::InputStream(header_from.path(), begin, end),
                                                   header_from.path(), *header_from.state_->csv, first_line)) {}

std::vector<std::string> TrajectoryReader::RunIds() const {
  std::vector<std::string> out;
  out.reserve(state_->finished.size());
  for (const auto& [id, line] : state_->finished) out.push_back(id);
  return out;
}

std::size_t TrajectoryReader::run_column() const { return state_->c_run->index; }
std::uint64_t TrajectoryReader::offset() const { return state_->csv->offset(); }
std::size_t TrajectoryReader::next_line() const { return state_->csv->next_line(); }

namespace {
/// [b, e) without blanks and a trailing \r.
std::string_view TrimRow(const char* b, const char* e) {
  while (e > b && (e[-1] == '\r' || e[-1] == ' ' || e[-1] == '\t')) --e;
  while (b < e && (*b == ' ' || *b == '\t')) ++b;
  return std::string_view(b, static_cast<std::size_t>(e - b));
}

/// Cell `column` of the row [b, e) (no quotes in it), or nullopt.
std::optional<std::string_view> CellOf(const char* b, const char* e, std::size_t column) {
  for (std::size_t k = 0; k < column; ++k) {
    const auto* comma = static_cast<const char*>(std::memchr(b, ',', static_cast<std::size_t>(e - b)));
    if (comma == nullptr) return std::nullopt;
    b = comma + 1;
  }
  const auto* comma = static_cast<const char*>(std::memchr(b, ',', static_cast<std::size_t>(e - b)));
  return TrimRow(b, comma != nullptr ? comma : e);
}
}  // namespace

std::optional<std::uint64_t> FindRunBoundary(const std::string& path, std::uint64_t target, std::size_t run_column) {
  constexpr std::uint64_t kWindow = std::uint64_t{8} << 20;
  detail::InputStream probe(path);
  if (!probe.sized() || target == 0 || target >= probe.size()) return std::nullopt;
  const std::uint64_t end = std::min(probe.size(), target + kWindow);
  detail::InputStream in(path, target - 1, end);  // from the byte before: a row may start at target
  std::string window(static_cast<std::size_t>(end - target + 1), '\0');
  std::size_t got = 0;
  while (got < window.size()) {
    const std::size_t n = in.Read(window.data() + got, window.size() - got);
    if (n == 0) break;
    got += n;
  }
  window.resize(got);
  if (window.find('"') != std::string::npos) return std::nullopt;
  std::size_t pos = window.find('\n');  // the first row that starts at or after target
  std::optional<std::string_view> previous;
  while (pos != std::string::npos && pos + 1 < window.size()) {
    const std::size_t b = pos + 1;
    const std::size_t e = window.find('\n', b);
    if (e == std::string::npos) break;  // the last row may be cut by the window
    const std::string_view row = TrimRow(window.data() + b, window.data() + e);
    if (!row.empty() && row.front() != '#') {
      const auto id = CellOf(window.data() + b, window.data() + e, run_column);
      if (!id) return std::nullopt;
      if (previous && *id != *previous) return target - 1 + b;
      previous = id;
    }
    pos = e;
  }
  return std::nullopt;
}

std::size_t LineAtOffset(const std::string& path, std::uint64_t offset) {
  detail::InputStream in(path, 0, offset);
  std::vector<char> buf(std::size_t{1} << 20);
  std::size_t lines = 1;
  for (;;) {
    const std::size_t n = in.Read(buf.data(), buf.size());
    if (n == 0) break;
    lines += static_cast<std::size_t>(std::count(buf.data(), buf.data() + n, '\n'));
  }
  return lines;
}

TrajectoryReader::TrajectoryReader(const std::string& path)
    : TrajectoryReader(std::make_unique<CsvReader>(detail::InputStream(path), path)) {}

TrajectoryReader::TrajectoryReader(std::string_view text, const std::string& name, std::size_t max_chunk,
                                   std::size_t buffer_bytes)
    : TrajectoryReader(std::make_unique<CsvReader>(text, name, max_chunk, buffer_bytes)) {}

TrajectoryReader::~TrajectoryReader() = default;
TrajectoryReader::TrajectoryReader(TrajectoryReader&&) noexcept = default;
TrajectoryReader& TrajectoryReader::operator=(TrajectoryReader&&) noexcept = default;

const std::string& TrajectoryReader::path() const { return state_->csv->name(); }

bool TrajectoryReader::has_ticks() const { return state_->ticks; }

bool TrajectoryReader::NextRun(TrajectoryRun& out) {
  State& s = *state_;
  CsvReader& csv = *s.csv;
  for (;;) {
    if (!csv.Next()) {
      if (!s.have_current) return false;
      s.FinishRun();
      std::swap(out, s.current);
      s.have_current = false;
      return true;
    }
    // Run id and direction are validated (Text) when a run starts; later rows
    // only compare them with the run's, which they must equal.
    std::string_view run_id = csv.cell(s.c_run->index);
    std::string_view direction = csv.cell(s.c_dir->index);
    if (!s.have_current || run_id != s.current.run) {
      run_id = csv.Text(*s.c_run);
      direction = csv.Text(*s.c_dir);
      const bool handed_out = s.have_current;
      if (handed_out) {
        // The run before is complete: check it, hand it out, and reuse the
        // caller's previous run (its vectors' capacity) for the new one.
        s.FinishRun();
        s.CheckNewId(run_id);
        std::swap(out, s.current);
      }
      s.StartRun(run_id, direction);
      s.have_current = true;
      s.AddRow();
      if (handed_out) return true;
      continue;
    }
    if (direction != s.current.direction && CanonicalDirection(direction) != s.current.direction) {
      direction = csv.Text(*s.c_dir);
      csv.FailCell(s.c_dir->index,
                   fmt::format("direction changes from {} to {} within run {} (a run keeps one direction; give "
                               "each run its own id)",
                               QuoteForMessage(s.current.direction), QuoteForMessage(direction),
                               QuoteForMessage(s.current.run)));
    }
    s.AddRow();
  }
}

TrajectoryData TrajectoryReader::ReadAll() {
  TrajectoryData data;
  data.path = path();
  for (;;) {
    TrajectoryRun run;
    if (!NextRun(run)) break;
    // Give back capacity that growth left far beyond the run's size.
    if (run.t_s.capacity() > run.size() + run.size() / 4 + 1024) {
      for (auto* v : {&run.t_s, &run.dist_left_m, &run.dist_right_m, &run.gt_x_m, &run.gt_y_m, &run.gt_theta_rad}) {
        v->shrink_to_fit();
      }
      run.ticks_left.shrink_to_fit();
      run.ticks_right.shrink_to_fit();
      run.lines.shrink_to_fit();
    }
    data.runs.push_back(std::move(run));
  }
  return data;
}

TrajectoryData ParseTrajectoryCsv(std::string_view text, const std::string& name) {
  return TrajectoryReader(text, name).ReadAll();
}

TrajectoryData ReadTrajectoryCsv(const std::string& path) { return TrajectoryReader(path).ReadAll(); }

}  // namespace umbmark::io
