// Reads the runs of a trajectory CSV on a second thread while the caller
// works on the run before (`evaluate`: parsing and evaluating overlap, so the
// whole process takes about the longer of the two instead of their sum).
//
// The caller sees exactly what TrajectoryReader::NextRun gives, in the same
// order, and a reader fault (InputError with file, line and column) is
// rethrown by NextRun at the run where it happened, after every run before
// it was handed out. Memory: the run in the caller's hands, one run ready
// and one being read (three runs instead of two); the vectors' capacity is
// recycled between them.
#pragma once

#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

#include "core/runs.hpp"
#include "formats/trajectory_csv.hpp"

namespace umbmark::io {

class RunPrefetcher {
 public:
  /// Starts reading `reader` (which must outlive this object) on a thread.
  explicit RunPrefetcher(TrajectoryReader& reader);
  /// Stops the thread (after the run it is reading) and joins it.
  ~RunPrefetcher();
  RunPrefetcher(const RunPrefetcher&) = delete;
  RunPrefetcher& operator=(const RunPrefetcher&) = delete;

  /// The next run into `run` (its old contents' capacity goes back to the
  /// reader); false after the last run. Rethrows the reader's exception.
  bool NextRun(TrajectoryRun& run);

 private:
  void Loop();

  TrajectoryReader& reader_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<TrajectoryRun> ready_;  ///< a run read and not yet taken
  TrajectoryRun spare_;                 ///< capacity handed back by the caller
  bool have_spare_ = false;
  bool done_ = false;                   ///< the reader has no more runs (or failed)
  bool stop_ = false;                   ///< the consumer is gone
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace umbmark::io
