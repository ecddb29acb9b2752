// Reader for the contract's trajectory CSV (one row per encoder sample):
//   run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad
// ticks_* are cumulative signed 64-bit counts; instead dist_left_m,
// dist_right_m (cumulative travel) may be given. Ground-truth cells may be
// empty per row (all three together); each run needs ground truth at its
// first and last sample. A run is identified by its run id: its rows must be
// contiguous, its direction constant and t_s strictly increasing. Unknown
// columns are an error (a typo must not silently drop data).
//
// Streaming: TrajectoryReader hands out one run at a time, so a consumer
// that needs one run at a time (evaluate) holds the largest run in memory,
// not the file. Memory beyond the run in hand: the read buffer (1 MiB) and
// the ids of the runs already read (to report a run id that comes back
// after another run: an error naming both lines).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/runs.hpp"

namespace umbmark::io {

namespace detail {
class CsvReader;
}

/// Reads the runs of a trajectory CSV one by one. Faults (InputError with
/// file, line, column): missing/duplicated/unknown-unit column, text or
/// NaN/Inf in a number, truncated row, non-increasing time, a run id that
/// reappears after another run (rows of a run must be contiguous), missing
/// ground truth at a run's first/last sample, partial ground truth in a row,
/// a direction change within a run, a tick count that is not a signed 64-bit
/// integer, an encoder jump that can only be a counter wrap (|delta| >= 2^30
/// ticks between two samples), an empty file or no data rows, a line over
/// 1 MiB. Header faults are thrown by the constructor, the others by
/// NextRun() when it reaches them (a run is handed out only once its last
/// row has been read and checked).
class TrajectoryReader {
 public:
  /// Opens a file (read with read() in 1 MiB chunks, never mapped).
  explicit TrajectoryReader(const std::string& path);
  /// Text in memory; `name` is used in error messages. `max_chunk` > 0 feeds
  /// the tokenizer at most that many bytes at a time and `buffer_bytes` > 0
  /// sets its initial buffer (tests of chunk boundaries).
  TrajectoryReader(std::string_view text, const std::string& name, std::size_t max_chunk = 0,
                   std::size_t buffer_bytes = 0);
  /// Continues from a tokenizer whose header has been read (ReadRunFile).
  explicit TrajectoryReader(std::unique_ptr<detail::CsvReader> csv);
  /// The bytes [begin, end) of the file `header_from` reads, a part that
  /// starts at a run boundary (FindRunBoundary), with `header_from`'s header;
  /// `first_line` is the file's line number at `begin`.
  TrajectoryReader(const TrajectoryReader& header_from, std::uint64_t begin, std::uint64_t end,
                   std::size_t first_line);
  ~TrajectoryReader();
  TrajectoryReader(TrajectoryReader&&) noexcept;
  TrajectoryReader& operator=(TrajectoryReader&&) noexcept;

  /// The name given for messages (the path for a file).
  const std::string& path() const;
  /// True when the file gives ticks_* (false: dist_*_m).
  bool has_ticks() const;

  /// Reads the next run into `run` (replacing its contents; the capacity of
  /// its vectors is reused). Returns false after the last run.
  bool NextRun(TrajectoryRun& run);

  /// Reads every remaining run.
  TrajectoryData ReadAll();

  /// The ids of the runs handed out so far.
  std::vector<std::string> RunIds() const;
  /// Index of the run column in each row.
  std::size_t run_column() const;
  /// Byte offset of the next unread row (after the header: where the data
  /// start) and its line number.
  std::uint64_t offset() const;
  std::size_t next_line() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// Where a trajectory CSV file may be cut into parts read in parallel: the
/// byte offset of the first row at or after `target` whose run id differs
/// from the row before it (so no run spans the cut), searched within a few
/// MiB; `run_column` is TrajectoryReader::run_column(). Nullopt when there is
/// none there or the rows there hold a quote (a quoted cell may span lines).
std::optional<std::uint64_t> FindRunBoundary(const std::string& path, std::uint64_t target, std::size_t run_column);

/// The line number of byte `offset` of the file (1 + the line breaks before it).
std::size_t LineAtOffset(const std::string& path, std::uint64_t offset);

/// Reads a whole trajectory CSV file (TrajectoryReader(path).ReadAll()).
TrajectoryData ReadTrajectoryCsv(const std::string& path);

/// Same, from text in memory; `name` is used in error messages.
TrajectoryData ParseTrajectoryCsv(std::string_view text, const std::string& name);

}  // namespace umbmark::io
